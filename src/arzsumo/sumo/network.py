"""The ramp-metering network: plain XML sources and the netconvert build.

The layout is drawn in docs/sumo.md, "Network" (the light ``meter`` has one signal, link
index 0). With ``approach_length`` La > 0 an ``approach`` edge Q(-La) -> A(0), like
``main``, comes first: mainline vehicles are inserted there and may queue, so a queue
from the merge that reaches x = 0 no longer blocks insertion. With ``approach_piece``
P > 0 it is cut into ceil(La / P) equal edges ``approach0``, ``approach1``, ... in driving
order: the same road, on which SUMO's sublane step costs less (docs/sumo.md, "What
SUMO's step costs").
"""

from __future__ import annotations

import contextlib
import logging
import math
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, fields
from pathlib import Path
from xml.sax.saxutils import quoteattr

from arzsumo.errors import require
from arzsumo.io import atomic_file
from arzsumo.sumo.paths import NET_FILE, SumoError, sumo_binary

log = logging.getLogger(__name__)

MAIN, MERGE, DOWN, RAMP_UP, RAMP_DN = "main", "merge", "down", "ramp_up", "ramp_dn"
APPROACH = "approach"
METER_TL = "meter"
#: signals (links) of the light ``meter``: its state strings are this long
METER_LINKS = 1
SOURCE_FILES = ("ramp.nod.xml", "ramp.edg.xml", "ramp.con.xml", "ramp.tll.xml")


@dataclass(frozen=True)
class NetworkSpec:
    """Geometry and speed limits of the ramp network (SI: m, m/s).

    ``length`` is L, exactly the ``main`` edge's; ``lane_width`` the mainline lane's W;
    ``ramp_length`` the queue storage ``ramp_up`` upstream of the meter, ``ramp_dn_length``
    the ramp from the meter to the merge; ``approach_length`` 0: no approach edge,
    ``approach_piece`` 0: one edge (:func:`approach_edges`).
    """

    length: float = 1000.0
    lane_width: float = 6.5
    main_speed: float = 80.0 / 3.6
    merge_length: float = 150.0
    acc_lane_width: float = 3.5
    down_length: float = 500.0
    down_speed: float = 50.0 / 3.6
    ramp_length: float = 300.0
    ramp_dn_length: float = 120.0
    ramp_speed: float = 50.0 / 3.6
    approach_length: float = 0.0
    approach_piece: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in ("approach_length", "approach_piece"):
                require(isinstance(value, int | float) and 0 <= value < 1e6, f.name, value,
                        "a length in [0, 1e6) m (0: no approach edge / one edge)")
            else:
                require(isinstance(value, int | float) and value > 0, f.name, value,
                        "a number greater than 0")
        require(self.lane_width <= 20.0, "lane_width", self.lane_width, "at most 20 m")


def xml_file(root: str, lines: list[str]) -> str:
    """An XML file of element ``root`` holding ``lines``, each indented by four spaces."""
    body = "\n".join(f"    {line}" for line in lines)
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<{root}>\n{body}\n</{root}>\n'


def _attrs(**kw: object) -> str:
    return " ".join(f"{k}={quoteattr(_fmt(v))}" for k, v in kw.items())


def _fmt(v: object) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def network_sources(spec: NetworkSpec) -> dict[str, str]:
    """The four plain-XML sources (file name -> text) of the network ``spec``."""
    L = spec.length
    mx, my = L - 0.6 * spec.ramp_dn_length, -0.8 * spec.ramp_dn_length
    nodes = [
        f'<node {_attrs(id="A", x=0.0, y=0.0, type="priority")}/>',
        f'<node {_attrs(id="B", x=L, y=0.0, type="priority")}/>',
        f'<node {_attrs(id="C", x=L + spec.merge_length, y=0.0, type="priority")}/>',
        f'<node {_attrs(id="D", x=L + spec.merge_length + spec.down_length, y=0.0)}/>',
        f'<node {_attrs(id="M", x=mx, y=my, type="traffic_light", tl=METER_TL)}/>',
        f'<node {_attrs(id="R", x=mx - 0.6 * spec.ramp_length, y=my - 0.8 * spec.ramp_length)}/>',
    ]
    edges = [
        f'<edge {_attrs(id=MAIN, **{"from": "A"}, to="B", numLanes=1, speed=spec.main_speed, priority=3, length=L, width=spec.lane_width)}/>',  # noqa: E501
        f'<edge {_attrs(id=MERGE, **{"from": "B"}, to="C", numLanes=2, speed=spec.main_speed, priority=3, length=spec.merge_length)}>',  # noqa: E501
        f'    <lane {_attrs(index=0, width=spec.acc_lane_width)}/>',
        f'    <lane {_attrs(index=1, width=spec.lane_width)}/>',
        "</edge>",
        f'<edge {_attrs(id=DOWN, **{"from": "C"}, to="D", numLanes=1, speed=spec.down_speed, priority=3, length=spec.down_length, width=spec.lane_width)}/>',  # noqa: E501
        f'<edge {_attrs(id=RAMP_UP, **{"from": "R"}, to="M", numLanes=1, speed=spec.ramp_speed, priority=1, length=spec.ramp_length, width=spec.acc_lane_width)}/>',  # noqa: E501
        f'<edge {_attrs(id=RAMP_DN, **{"from": "M"}, to="B", numLanes=1, speed=spec.ramp_speed, priority=1, length=spec.ramp_dn_length, width=spec.acc_lane_width)}/>',  # noqa: E501
    ]
    cons = [
        f'<connection {_attrs(**{"from": MAIN}, to=MERGE, fromLane=0, toLane=1)}/>',
        f'<connection {_attrs(**{"from": RAMP_DN}, to=MERGE, fromLane=0, toLane=0)}/>',
        f'<connection {_attrs(**{"from": MERGE}, to=DOWN, fromLane=1, toLane=0)}/>',
        f'<connection {_attrs(**{"from": RAMP_UP}, to=RAMP_DN, fromLane=0, toLane=0)}/>',
    ]
    if spec.approach_length > 0:
        _add_approach(spec, nodes, edges, cons)
    tll = [
        f'<tlLogic {_attrs(id=METER_TL, type="static", programID="0", offset=0)}>',
        f'    <phase {_attrs(duration=3, state="G")}/>',
        f'    <phase {_attrs(duration=1, state="y")}/>',
        f'    <phase {_attrs(duration=2, state="r")}/>',
        "</tlLogic>",
        f'<connection {_attrs(**{"from": RAMP_UP}, to=RAMP_DN, fromLane=0, toLane=0, tl=METER_TL, linkIndex=0)}/>',  # noqa: E501
    ]
    return {
        "ramp.nod.xml": xml_file("nodes", nodes),
        "ramp.edg.xml": xml_file("edges", edges),
        "ramp.con.xml": xml_file("connections", cons),
        "ramp.tll.xml": xml_file("tlLogics", tll),
    }


def approach_edges(approach_length: float, approach_piece: float = 0.0) -> tuple[str, ...]:
    """The approach's edge IDs in driving order: none without an approach, ``approach``
    uncut, else ``approach0`` ... ``approach{n-1}``, n = ceil(La / P) (a last piece
    within a millimetre of P does not make another)."""
    if approach_length <= 0:
        return ()
    n = max(1, math.ceil((approach_length - 1e-3) / approach_piece)) if approach_piece else 1
    return (APPROACH,) if n == 1 else tuple(f"{APPROACH}{k}" for k in range(n))


def _add_approach(spec: NetworkSpec, nodes: list[str], edges: list[str],
                  cons: list[str]) -> None:
    """Prepend the approach's nodes (Q at -La, then the cuts), its equal edges (explicit
    lengths) and their connections, the last into ``main``."""
    ids = approach_edges(spec.approach_length, spec.approach_piece)
    piece = spec.approach_length / len(ids)
    ends = ["Q"] + [f"Q{k}" for k in range(1, len(ids))] + ["A"]
    for k, node in enumerate(ends[:-1]):
        kind = {} if k == 0 else {"type": "priority"}
        nodes.append(f'<node {_attrs(id=node, x=-spec.approach_length + k * piece, y=0.0, **kind)}/>')  # noqa: E501
    new_edges = [f'<edge {_attrs(id=e, **{"from": ends[k]}, to=ends[k + 1], numLanes=1, speed=spec.main_speed, priority=3, length=piece, width=spec.lane_width)}/>'  # noqa: E501
                 for k, e in enumerate(ids)]
    edges[:0] = new_edges
    cons[:0] = [f'<connection {_attrs(**{"from": e}, to=nxt, fromLane=0, toLane=0)}/>'
                for e, nxt in zip(ids, (*ids[1:], MAIN), strict=True)]


def write_if_changed(path: Path, data: bytes) -> bool:
    """Write ``data`` to ``path`` (atomically) unless the file already holds exactly these
    bytes; return whether it was written. Untouched files keep their mtime and git status."""
    with contextlib.suppress(FileNotFoundError):
        if path.read_bytes() == data:
            return False
    with atomic_file(path) as tmp:
        tmp.write_bytes(data)
    return True


def write_sources(spec: NetworkSpec, out_dir: Path) -> list[Path]:
    """Write the plain-XML sources of ``spec`` into ``out_dir`` (changed files only)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, text in network_sources(spec).items():
        write_if_changed(out_dir / name, text.encode("utf-8"))
    return [out_dir / name for name in SOURCE_FILES]


#: netconvert's header comment starts with the build time; no option drops it (SUMO 1.28),
#: so it is cut out to make the net file a function of its sources and SUMO's version
_STAMP = re.compile(rb"<!-- generated on \S+ by ")


def deterministic_net(data: bytes) -> bytes:
    """netconvert output without the build timestamp (the configuration comment stays)."""
    return _STAMP.sub(b"<!-- generated by ", data, count=1)


def run_netconvert(src_dir: Path, out_dir: Path) -> tuple[Path, bool]:
    """Build ``ramp.net.xml`` in ``out_dir`` from the sources in ``src_dir``; its path and
    whether it was (re)written (only when its bytes differ). netconvert runs in a temporary
    directory on copies of the sources, so the header comment names only ``ramp.*.xml``."""
    missing = [n for n in SOURCE_FILES if not (src_dir / n).is_file()]
    if missing:
        raise SumoError(f"sources = {missing} are missing in {src_dir}; allowed: a directory "
                        "with the files written by `arzsumo build-net`")
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="arzsumo-netconvert-") as work:
        for name in SOURCE_FILES:
            shutil.copyfile(src_dir / name, Path(work) / name)
        cmd = [str(sumo_binary("netconvert")),
               "--node-files", "ramp.nod.xml", "--edge-files", "ramp.edg.xml",
               "--connection-files", "ramp.con.xml", "--tllogic-files", "ramp.tll.xml",
               "--no-turnarounds", "true", "--no-internal-links", "false",
               "--output-file", NET_FILE, "--no-warnings", "true"]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False, cwd=work)
        if proc.returncode != 0:
            lines = [ln for ln in (proc.stderr or proc.stdout).splitlines() if ln.strip()]
            raise SumoError(f"netconvert failed: {lines[-1] if lines else proc.returncode}")
        data = deterministic_net((Path(work) / NET_FILE).read_bytes())
    changed = write_if_changed(out_dir / NET_FILE, data)
    log.debug("network %s %s", "written to" if changed else "unchanged in", out_dir / NET_FILE)
    return out_dir / NET_FILE, changed


def edge_lengths(net_file: Path) -> dict[str, float]:
    """Lengths (m) of the non-internal edges of a built network, read with sumolib."""
    import sumolib

    return {e.getID(): float(e.getLength()) for e in sumolib.net.readNet(str(net_file)).getEdges()}


def build_network(out_dir: Path, spec: NetworkSpec | None = None, *,
                  write: bool = True) -> Path:
    """Write the sources of ``spec`` (unless ``write`` is False) and build the network,
    checked to have the mainline (and the approach) exactly as long as ``spec`` says."""
    return rebuild_network(out_dir, spec, write=write)[0]


def rebuild_network(out_dir: Path, spec: NetworkSpec | None = None, *,
                    write: bool = True) -> tuple[Path, bool]:
    """:func:`build_network`, also telling whether ``ramp.net.xml`` was (re)written: an
    unchanged network is not rewritten (same bytes, same mtime, clean git tree)."""
    spec = spec or NetworkSpec()
    try:
        if write:
            write_sources(spec, out_dir)
        net, changed = run_netconvert(out_dir, out_dir)
    except OSError as exc:
        raise SumoError(f"out = {str(out_dir)!r} cannot be written: {exc.strerror}; allowed: "
                        "a writable directory") from None
    lengths = edge_lengths(net)
    ids = approach_edges(spec.approach_length, spec.approach_piece)
    wanted = {MAIN: spec.length} | {e: spec.approach_length / len(ids) for e in ids}
    for edge, length in wanted.items():
        if abs(lengths.get(edge, -1.0) - length) > 1e-6:
            raise SumoError(f"{edge} edge length = {lengths.get(edge)} m differs from the "
                            f"requested {length} m")
    return net, changed


def approach_of(net_file: Path) -> tuple[str, ...]:
    """The approach's edge IDs of a built network in driving order (:func:`approach_edges`);
    none without an approach."""
    return _approach_ids(edge_lengths(net_file))


def _approach_ids(lengths: dict[str, float]) -> tuple[str, ...]:
    if APPROACH in lengths:
        return (APPROACH,)
    pieces = sorted((int(m.group(1)), e) for e in lengths
                    if (m := re.fullmatch(rf"{APPROACH}(\d+)", e)))
    return tuple(e for _, e in pieces)


def approach_length_of(net_file: Path) -> float:
    """Length (m) of the approach of a built network, all its pieces; 0 without one."""
    lengths = edge_lengths(net_file)
    return sum(lengths[e] for e in _approach_ids(lengths))
