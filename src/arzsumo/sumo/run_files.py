"""What a run keeps of SUMO for its results directory: the configuration it ran, its FCD
(docs/outputs.md, "run.sumocfg and sumo/").

The files are gathered under :func:`~arzsumo.sumo.paths.scratch_dir` while the run lasts
(:class:`RunFiles`) and placed into the results directory by :meth:`RunFiles.place`:
hard-linked, or copied in chunks across file systems, never read into memory (an FCD
file is large).
"""

from __future__ import annotations

import os
import shutil
import tempfile
import weakref
from collections.abc import Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.demand import sumocfg_text
from arzsumo.sumo.meter_release import nominal_phases
from arzsumo.sumo.network import METER_LINKS, METER_TL
from arzsumo.sumo.paths import SumoError, scratch_dir

#: names inside the results directory
CONFIG_FILE, SUMO_DIR, METER_FILE, FCD_FILE = "run.sumocfg", "sumo", "meter.add.xml", "fcd.xml.gz"
#: programID of the nominal plan in ``meter.add.xml`` (the network's own program is "0";
#: SUMO runs the program loaded last)
METER_PROGRAM = "nominal"


def meter_program_text(cfg: SumoConfig) -> str:
    """An additional file with the nominal plan of the meter as a static ``tlLogic``
    (durations in s; :func:`~arzsumo.sumo.meter_release.nominal_phases`)."""
    lay = cfg.layout
    signal = (lambda state: state * METER_LINKS) if lay is None else lay.signal
    tl_id = METER_TL if lay is None else lay.meter_tl
    phases = [f'        <phase duration="{n * cfg.step_length:.6g}" '
              f'state={quoteattr(signal(state))}/>' for state, n in nominal_phases(cfg)]
    return "\n".join([
        '<?xml version="1.0" encoding="UTF-8"?>', "<additional>",
        f'    <tlLogic id={quoteattr(tl_id)} type="static" programID="{METER_PROGRAM}" '
        'offset="0">',
        *phases, "    </tlLogic>", "</additional>"]) + "\n"


def _unique(name: str, taken: set[str]) -> str:
    """``name``, or ``2_name``, ``3_name``, ... when it is taken: two of a user's route
    files may share a name in different directories, or take the run's own."""
    k, out = 1, name
    while out in taken:
        k += 1
        out = f"{k}_{name}"
    return out


class RunFiles:
    """A directory laid out as the results directory will be, gathered during a run.

    Created under :func:`~arzsumo.sumo.paths.scratch_dir` (inside the claimed output of
    ``arzsumo run``), removed by :meth:`remove` or when the object is collected.
    """

    def __init__(self, under: Path | None = None) -> None:
        self.root = Path(tempfile.mkdtemp(prefix="arzsumo-keep-", dir=under or scratch_dir()))
        self._finalizer = weakref.finalize(self, shutil.rmtree, str(self.root), True)

    def keep_config(self, net: Path, route: Path, additional: Sequence[Path],
                    cfg: SumoConfig) -> Path:
        """Copy the run's network, route and additional files into ``sumo/``, add the
        meter's nominal program and write ``run.sumocfg``; return its path."""
        sub = self.root / SUMO_DIR
        sub.mkdir(exist_ok=True)
        names: list[str] = []
        routes = cfg.layout.route_files if cfg.layout is not None else ()
        for src in (net, route, *additional, *routes):
            name = _unique(Path(src).name, {Path(n).name for n in names} | {METER_FILE})
            shutil.copyfile(src, sub / name)
            names.append(f"{SUMO_DIR}/{name}")
        (sub / METER_FILE).write_text(meter_program_text(cfg), encoding="utf-8")
        config = self.root / CONFIG_FILE
        n = 2 + len(additional)
        config.write_text(sumocfg_text(names[0], ",".join([names[1], *names[n:]]), cfg,
                                       [*names[2:n], f"{SUMO_DIR}/{METER_FILE}"]),
                          encoding="utf-8")
        return config

    def adopt(self, src: Path, name: str) -> Path:
        """Move ``src`` (a SUMO output of the run) in as ``name`` (a rename on one file
        system); a missing ``src`` is a SumoError."""
        if not Path(src).is_file():
            raise SumoError(f"SUMO wrote no {Path(src).name} in {str(Path(src).parent)!r}; "
                            "allowed: a run started with that output")
        return Path(shutil.move(src, self.root / name))

    def files(self) -> list[Path]:
        """The kept files, relative to the root, sorted."""
        return sorted(p.relative_to(self.root) for p in self.root.rglob("*") if p.is_file())

    def place(self, dest: Path) -> list[Path]:
        """Put every kept file under ``dest`` at its relative path (hard link, else a
        chunked copy); return the paths written. The kept files stay (placeable again)."""
        out = []
        for rel in self.files():
            target = Path(dest) / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            try:
                os.link(self.root / rel, target)
            except OSError:   # another file system, or no hard links there
                shutil.copyfile(self.root / rel, target)
            out.append(target)
        return out

    def copy(self, under: Path | None = None) -> RunFiles:
        """A new gathering (in ``under``, default the scratch directory) with copies of
        the files kept so far: for a run that branches off this one
        (:mod:`arzsumo.bridge.branches`)."""
        other = RunFiles(under)
        shutil.copytree(self.root, other.root, dirs_exist_ok=True)
        return other

    def remove(self) -> None:
        """Remove the gathered files now (safe to call twice)."""
        self._finalizer()
