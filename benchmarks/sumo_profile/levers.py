"""Time candidate levers on SUMO's step against a kept run configuration, and say which leave
the stream bit-identical.

    python benchmarks/sumo_profile/levers.py RUN_DIR [--end 400] [--reps 3] [--seeds 213,1,2]
        [--only NAME,NAME] [--out DIR]

RUN_DIR is a directory that `arzsumo run` kept (run.sumocfg and sumo/). Every lever is a copy
of that configuration under DIR (default: a temporary directory), changed one way: a sumo
option, a vType attribute in the route file, a network rebuilt with netconvert from the kept
network's plain sources, or an additional file left out. Nothing in RUN_DIR is changed.

For each lever the `sumo` binary runs the baseline (B) and the lever (A) in turn, A B A B ...,
REPS times each, on the span [0, END] s; a run's CPU time is user + system of the finished
child (os.wait4). The ratio is the median of the pairwise ratios A/B. Both write tripinfo
(with unfinished vehicles, 6 decimals) so the stream of the first seed is compared for free;
a lever whose tripinfo equals the baseline's on that seed is run on the other seeds as well.
Bit-identical means every vehicle's tripinfo line (depart, arrival, route length, waiting
time, time loss, ...) equals the baseline's on every seed.

Prints one line per lever (CPU ratio, CPU s of A and B, bit-identical, vehicles inserted,
arrived, mean travel time of the arrived, mean time loss) and writes levers.json to DIR.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import sumo

SUMO_BIN = Path(sumo.SUMO_HOME) / "bin"


@dataclass
class Lever:
    """A change to the kept configuration: sumo options, vType attributes, a network edit."""

    name: str
    what: str
    options: tuple[str, ...] = ()
    vtype: dict[str, str] = field(default_factory=dict)
    net: Callable[[Path], dict[str, list[str]]] | None = None   # edits plain sources
    drop_additional: tuple[str, ...] = ()
    with_tripinfo: bool = True      # False: the lever removes the tripinfo output itself


# -- network edits (on the plain sources of the kept network) ----------------------------------
def _edges(plain: Path) -> ET.ElementTree:
    return ET.parse(plain / "p.edg.xml")


def merge_length(length: float) -> Callable[[Path], dict[str, list[str]]]:
    """The acceleration lane (edge `merge`) LENGTH m instead of 150 m; the rest unchanged."""
    def edit(plain: Path) -> dict[str, list[str]]:
        tree = _edges(plain)
        edge = tree.getroot().find("edge[@id='merge']")
        old = float(edge.get("length"))
        edge.set("length", f"{length:.2f}")
        tree.write(plain / "p.edg.xml")
        nodes = ET.parse(plain / "p.nod.xml")
        for node in nodes.getroot().iter("node"):
            if node.get("id") in ("C", "D"):
                node.set("x", f"{float(node.get('x')) + length - old:.2f}")
        nodes.write(plain / "p.nod.xml")
        return {}
    return edit


def split_edge(edge_id: str, pieces: int) -> Callable[[Path], dict[str, list[str]]]:
    """Edge EDGE_ID cut into PIECES equal edges in a row (priority junctions, one lane each);
    routes through it name the pieces instead."""
    def edit(plain: Path) -> dict[str, list[str]]:
        tree = _edges(plain)
        root = tree.getroot()
        edge = root.find(f"edge[@id='{edge_id}']")
        nodes = ET.parse(plain / "p.nod.xml")
        byid = {n.get("id"): n for n in nodes.getroot().iter("node")}
        a, b = byid[edge.get("from")], byid[edge.get("to")]
        xa, ya, xb, yb = (float(a.get("x")), float(a.get("y")), float(b.get("x")),
                          float(b.get("y")))
        length = float(edge.get("length"))
        names = [f"{edge_id}_{k}" for k in range(pieces)]
        ends = [edge.get("from")] + [f"{edge_id}_n{k}" for k in range(1, pieces)] + [b.get("id")]
        for k in range(1, pieces):
            ET.SubElement(nodes.getroot(), "node", id=ends[k], type="priority",
                          x=f"{xa + (xb - xa) * k / pieces:.2f}",
                          y=f"{ya + (yb - ya) * k / pieces:.2f}")
        nodes.write(plain / "p.nod.xml")
        index = list(root).index(edge)
        root.remove(edge)
        for k, name in enumerate(names):
            piece = ET.Element("edge", dict(edge.attrib))
            piece.set("id", name)
            piece.set("from", ends[k])
            piece.set("to", ends[k + 1])
            piece.set("length", f"{length / pieces:.2f}")
            root.insert(index + k, piece)
        tree.write(plain / "p.edg.xml")
        cons = ET.parse(plain / "p.con.xml")
        for con in cons.getroot().iter("connection"):
            if con.get("from") == edge_id:
                con.set("from", names[-1])
            if con.get("to") == edge_id:
                con.set("to", names[0])
        cons.write(plain / "p.con.xml")
        return {edge_id: names}
    return edit


def rebuild_only(plain: Path) -> dict[str, list[str]]:
    """No change: the kept network rebuilt from its own plain sources (the control)."""
    return {}


LEVERS: list[Lever] = [
    Lever("tripinfo-off", "no tripinfo output (the baseline of every other line writes it)",
          with_tripinfo=False),
    Lever("run-outputs", "the outputs a run adds: tripinfo with undeparted, emissions device on "
          "every vehicle, edgedata, statistics",
          ("--tripinfo-output.write-undeparted", "true", "--device.emissions.probability", "1",
           "--edgedata-output", "{dir}/edgedata.xml", "--statistic-output",
           "{dir}/statistics.xml")),
    Lever("no-detectors", "the six induction loops (e1.add.xml, e1_down.add.xml) left out",
          drop_additional=("e1.add.xml", "e1_down.add.xml")),
    Lever("collision-none", "--collision.action none (no collision check at all)",
          ("--collision.action", "none")),
    Lever("no-junction-check", "--collision.check-junctions false",
          ("--collision.check-junctions", "false")),
    Lever("eager-insert-off", "--eager-insert false", ("--eager-insert", "false")),
    Lever("latres-1.3", "--lateral-resolution 1.3", ("--lateral-resolution", "1.3")),
    Lever("latres-3.25", "--lateral-resolution 3.25 (2 sublanes on the 6.5 m lane)",
          ("--lateral-resolution", "3.25")),
    Lever("lc-duration-2", "no sublanes, --lanechange.duration 2 (continuous lane change)",
          ("--lateral-resolution", "0", "--lanechange.duration", "2")),
    Lever("sublane-off", "no sublane model (--lateral-resolution 0): the limit",
          ("--lateral-resolution", "0")),
    Lever("step-0.2", "--step-length 0.2 (Krauss sigmaStep follows the step)",
          ("--step-length", "0.2")),
    Lever("step-0.25", "--step-length 0.25", ("--step-length", "0.25")),
    Lever("step-0.2-sigmastep-1", "--step-length 0.2, Krauss sigmaStep 1 s",
          ("--step-length", "0.2"), vtype={"sigmaStep": "1"}),
    Lever("action-step-0.2", "actionStepLength 0.2 s on every vType",
          vtype={"actionStepLength": "0.2"}),
    Lever("action-step-0.5", "actionStepLength 0.5 s on every vType",
          vtype={"actionStepLength": "0.5"}),
    Lever("lcSublane-0", "lcSublane 0 (shipped 1)", vtype={"lcSublane": "0"}),
    Lever("lcPushy-0", "lcPushy 0 (shipped 0.2)", vtype={"lcPushy": "0"}),
    Lever("lcAssertive-2", "lcAssertive 2 (shipped: SUMO's 1)", vtype={"lcAssertive": "2"}),
    Lever("latAlignment-center", "latAlignment center (shipped arbitrary)",
          vtype={"latAlignment": "center"}),
    Lever("lcLookaheadLeft-1", "lcLookaheadLeft 1 (shipped: SUMO's 2)",
          vtype={"lcLookaheadLeft": "1"}),
    Lever("maxSpeedLat-0.5", "maxSpeedLat 0.5 m/s (shipped 1)", vtype={"maxSpeedLat": "0.5"}),
    Lever("maxSpeedLat-2", "maxSpeedLat 2 m/s (shipped 1)", vtype={"maxSpeedLat": "2"}),
    Lever("lcSigma-0.1", "lcSigma 0.1 (shipped: SUMO's 0)", vtype={"lcSigma": "0.1"}),
    Lever("net-rebuilt", "the kept network rebuilt by netconvert from its plain sources",
          net=rebuild_only),
    Lever("merge-100", "acceleration lane 100 m (shipped 150 m)", net=merge_length(100)),
    Lever("merge-250", "acceleration lane 250 m (shipped 150 m)", net=merge_length(250)),
    Lever("approach-split-10", "the 2500 m approach cut into 10 edges of 250 m",
          net=split_edge("approach", 10)),
    Lever("approach-split-25", "the 2500 m approach cut into 25 edges of 100 m",
          net=split_edge("approach", 25)),
    Lever("split-10+collision-none", "approach in 10 edges and --collision.action none",
          ("--collision.action", "none"), net=split_edge("approach", 10)),
]


# -- building a lever's copy -------------------------------------------------------------------
def build(lever: Lever, run_dir: Path, dest: Path) -> Path:
    """Copy RUN_DIR's configuration to DEST with LEVER applied; return the sumocfg path."""
    if dest.exists():
        shutil.rmtree(dest)
    shutil.copytree(run_dir / "sumo", dest / "sumo")
    cfg_text = (run_dir / "run.sumocfg").read_text()
    for name in lever.drop_additional:
        cfg_text = re.sub(rf"sumo/{re.escape(name)},?", "", cfg_text)
        cfg_text = cfg_text.replace(',"/>', '"/>')
    rou = dest / "sumo" / "run.rou.xml"
    text = rou.read_text()
    for key, value in lever.vtype.items():
        def setattr_(m: re.Match[str], key: str = key, value: str = value) -> str:
            tag = m.group(0)
            if re.search(rf'\s{key}="', tag):
                return re.sub(rf'(\s{key}=")[^"]*"', rf'\g<1>{value}"', tag)
            return tag[:-2] + f' {key}="{value}"/>'
        text = re.sub(r"<vType\b[^>]*/>", setattr_, text)
    if lever.net is not None:
        plain = dest / "plain"
        plain.mkdir()
        subprocess.run([str(SUMO_BIN / "netconvert"), "--sumo-net-file",
                        str(dest / "sumo" / "ramp.net.xml"), "--plain-output-prefix",
                        str(plain / "p")], check=True, capture_output=True)
        renames = lever.net(plain)
        subprocess.run([str(SUMO_BIN / "netconvert"), "-n", str(plain / "p.nod.xml"),
                        "-e", str(plain / "p.edg.xml"), "-x", str(plain / "p.con.xml"),
                        "-i", str(plain / "p.tll.xml"), "--no-turnarounds", "true",
                        "--offset.disable-normalization", "true", "--no-warnings", "true",
                        "-o", str(dest / "sumo" / "ramp.net.xml")],
                       check=True, capture_output=True)
        for old, new in renames.items():
            text = re.sub(rf'(edges="[^"]*)\b{old}\b', rf'\1{" ".join(new)}', text)
    rou.write_text(text)
    cfg = dest / "run.sumocfg"
    cfg.write_text(cfg_text)
    return cfg


def command(cfg: Path, end: float, seed: int, options: tuple[str, ...], tripinfo: Path | None,
            ) -> list[str]:
    cmd = [str(SUMO_BIN / "sumo"), "-c", str(cfg), "--end", f"{end:g}", "--seed", str(seed),
           "--no-step-log", "true", "--no-warnings", "true", "--duration-log.disable", "true"]
    if tripinfo is not None:
        cmd += ["--tripinfo-output", str(tripinfo), "--tripinfo-output.write-unfinished", "true",
                "--precision", "6"]
    return cmd + [o.replace("{dir}", str(cfg.parent)) for o in options]


def cpu_run(cmd: list[str]) -> float:
    """User + system CPU seconds of one finished run of CMD."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"exit {proc.returncode}: {' '.join(cmd)}")
    return usage.ru_utime + usage.ru_stime


def trip_lines(path: Path) -> list[str]:
    """The tripinfo elements' opening tags, without the devices attribute (an output option
    adds devices, and the emissions device adds a child element)."""
    return [re.sub(r' devices="[^"]*"', "", ln.strip()).rstrip("/>")
            for ln in path.read_text().splitlines() if ln.strip().startswith("<tripinfo ")]


def stream_numbers(path: Path) -> dict[str, float]:
    """Vehicles inserted and arrived, mean travel time of the arrived, mean time loss."""
    trips = ET.parse(path).getroot().findall("tripinfo")
    arrived = [t for t in trips if float(t.get("arrival", "-1")) >= 0]
    return {"inserted": len(trips), "arrived": len(arrived),
            "mean_travel_s": round(statistics.fmean(float(t.get("duration")) for t in arrived), 2)
            if arrived else float("nan"),
            "mean_time_loss_s": round(statistics.fmean(float(t.get("timeLoss")) for t in trips), 2)
            if trips else float("nan")}


def measure(lever: Lever, base_cfg: Path, run_dir: Path, work: Path, end: float, reps: int,
            seeds: list[int]) -> dict[str, object]:
    cfg = build(lever, run_dir, work / lever.name)
    ti_a, ti_b = work / lever.name / "tripinfo.xml", work / "baseline" / f"tripinfo{seeds[0]}.xml"
    cmd_a = command(cfg, end, seeds[0], lever.options, ti_a if lever.with_tripinfo else None)
    cmd_b = command(base_cfg, end, seeds[0], (), ti_b)
    cpu_a, cpu_b = [], []
    for _ in range(reps):
        cpu_a.append(cpu_run(cmd_a))
        cpu_b.append(cpu_run(cmd_b))
    ratio = statistics.median(a / b for a, b in zip(cpu_a, cpu_b, strict=True))
    row: dict[str, object] = {
        "lever": lever.name, "what": lever.what, "ratio": round(ratio, 3),
        "cpu_a_s": round(statistics.median(cpu_a), 2),
        "cpu_b_s": round(statistics.median(cpu_b), 2),
        "cpu_a_all": [round(x, 2) for x in cpu_a], "cpu_b_all": [round(x, 2) for x in cpu_b]}
    if not lever.with_tripinfo:
        row["identical"] = "yes (by construction: an output only)"
        return row
    same = trip_lines(ti_a) == trip_lines(ti_b)
    row.update(stream_numbers(ti_a))
    row["baseline"] = stream_numbers(ti_b)
    checked = [seeds[0]]
    if same:
        for seed in seeds[1:]:
            tb = work / "baseline" / f"tripinfo{seed}.xml"
            if not tb.exists():
                cpu_run(command(base_cfg, end, seed, (), tb))
            ta = work / lever.name / f"tripinfo{seed}.xml"
            cpu_run(command(cfg, end, seed, lever.options, ta))
            checked.append(seed)
            if trip_lines(ta) != trip_lines(tb):
                same = False
                break
    row["identical"] = "yes" if same else "no"
    row["seeds_checked"] = checked
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path, help="a directory `arzsumo run` kept")
    parser.add_argument("--end", type=float, default=400.0, help="simulated span, s")
    parser.add_argument("--reps", type=int, default=3, help="runs of A and of B per lever")
    parser.add_argument("--seeds", default="213,1,2", help="seeds for the identity check")
    parser.add_argument("--only", default="", help="comma-separated lever names")
    parser.add_argument("--out", type=Path, default=None, help="work directory (kept)")
    parser.add_argument("--list", action="store_true", help="list the levers and exit")
    args = parser.parse_args()
    if args.list:
        for lever in LEVERS:
            print(f"{lever.name:22s} {lever.what}")
        return
    seeds = [int(s) for s in args.seeds.split(",")]
    work = args.out or Path(tempfile.mkdtemp(prefix="sumo_levers_"))
    work.mkdir(parents=True, exist_ok=True)
    base_cfg = build(Lever("baseline", "as kept"), args.run_dir.resolve(), work / "baseline")
    chosen = [lv for lv in LEVERS if not args.only or lv.name in args.only.split(",")]
    rows = []
    out_json = work / "levers.json"
    if out_json.exists():
        rows = [r for r in json.loads(out_json.read_text())
                if r["lever"] not in {lv.name for lv in chosen}]
    print(f"{'lever':22s} {'ratio':>6s} {'A s':>6s} {'B s':>6s}  {'identical':10s} "
          f"{'inserted':>8s} {'arrived':>7s} {'travel s':>8s} {'loss s':>7s}")
    for lever in chosen:
        t0 = time.monotonic()
        row = measure(lever, base_cfg, args.run_dir.resolve(), work, args.end, args.reps, seeds)
        rows.append(row)
        out_json.write_text(json.dumps(rows, indent=1))
        print(f"{lever.name:22s} {row['ratio']:6.3f} {row['cpu_a_s']:6.2f} {row['cpu_b_s']:6.2f}"
              f"  {str(row['identical'])[:10]:10s} {row.get('inserted', '')!s:>8s} "
              f"{row.get('arrived', '')!s:>7s} {row.get('mean_travel_s', '')!s:>8s} "
              f"{row.get('mean_time_loss_s', '')!s:>7s}   ({time.monotonic() - t0:.0f} s)",
              flush=True)
    print(f"written: {out_json}")


if __name__ == "__main__":
    main()
