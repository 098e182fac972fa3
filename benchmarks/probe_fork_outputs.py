"""Probe: a forked continuation with SUMO's own outputs (tripinfo, edge data, statistics).

SUMO opens its output files at start; a child forked at the end of the warm-up shares
those file descriptions with its parent. Each child copies the files written so far into
its own directory and puts its copy under the same descriptor (``os.dup2``, at the same
offset), continues 60 s and closes SUMO (which writes the unfinished trips and the
statistics). Its files must equal, line for line, those of an uninterrupted run of
``WARM`` + 60 s (but SUMO's header comment, with the time written and the paths, and the
statistics' wall-clock line). Usage::

    PYTHONPATH=src python benchmarks/probe_fork_outputs.py [WARM_S]

Measured (SUMO 1.28.0, warm-up 60 s): both children's tripinfo (690 lines), edge data
and statistics equal the uninterrupted run's.
"""
import os
import shutil
import sys
import tempfile
from pathlib import Path

from arzsumo.scenario import load_scenario
from arzsumo.sumo.network_measures import OUTPUT_FILES, network_options
from arzsumo.sumo.simulation import open_simulation

SC = load_scenario(Path(__file__).parents[1] / "scenarios/legacy_default.toml")
WARM = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
CFG = SC.sumo.with_(horizon=WARM + 60.0)
STEPS, FIRST = round(60 / CFG.step_length), round(WARM / CFG.step_length)


def redirect(src: Path, dst: Path) -> int:
    """Give this process its own copy of every file open under ``src`` (into ``dst``)."""
    n = 0
    for fd in map(int, os.listdir("/proc/self/fd")):
        try:
            target = Path(os.readlink(f"/proc/self/fd/{fd}"))
        except OSError:
            continue
        if target.parent == src:
            copy = dst / target.name
            shutil.copyfile(target, copy)
            new = os.open(copy, os.O_WRONLY)
            os.lseek(new, os.lseek(fd, 0, os.SEEK_CUR), os.SEEK_SET)
            os.dup2(new, fd)
            os.close(new)
            n += 1
    return n


def body(path: Path) -> list[str]:
    """The file without SUMO's header comment (time written, input and output paths)."""
    lines = path.read_text().splitlines()
    return [s for s in lines[lines.index("-->") + 1:] if "<performance " not in s]


if __name__ == "__main__":
    root = Path(tempfile.mkdtemp())
    whole, parent, kids = root / "whole", root / "parent", [root / "c1", root / "c2"]
    for d in kids:
        d.mkdir()
    with open_simulation(SC.params, CFG, extra_args=network_options(whole),
                         output_dir=whole) as sim:
        sim.run_until(CFG.horizon)
    with open_simulation(SC.params, CFG, extra_args=network_options(parent),
                         output_dir=parent) as sim:
        for _ in range(FIRST):
            sim.step()
        for kid in kids:
            pid = os.fork()
            if pid == 0:
                try:
                    print(f"child: {redirect(parent, kid)} files redirected", flush=True)
                    for _ in range(STEPS):
                        sim.lib.simulationStep()
                    sim.lib.close()
                finally:
                    os._exit(0)
            os.waitpid(pid, 0)
    for kid in kids:
        for name in OUTPUT_FILES:
            a, b = body(whole / name), body(kid / name)
            print(f"{kid.name} {name}: {'identical' if a == b else 'DIFFERENT'} "
                  f"({len(a)} lines / {len(b)})")
    shutil.rmtree(root)
