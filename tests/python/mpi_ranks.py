#!/usr/bin/python3
"""The studies under `mpirun -n 2` against one process (docs/mpi.md). ctest runs it
three times, labelled `mpi`, where the program is built with MPI:

  --part same     a 12-cell sweep (cases/block.toml, friction x width), a 16-cell corner of the
                  Gilbert stability map, a 4-frequency pulse curve and an IDA of a slender block
                  under 3 records, each run in one process
                  (2 threads) and under mpirun -n 2 (1 thread a rank): the same CSV byte for
                  byte once the wall_s column is removed; the JSON says how many ranks ran. The
                  map once more with a step budget that 6 cells exceed: the same failed rows,
                  exit status 1.
  --part resume   the MPI sweep with a journal; the journal cut after 5 of its 12 cells and half
                  a line (what a kill leaves); the MPI sweep resumed: the same CSV as the
                  uninterrupted one (the 5 kept cells with their journalled wall_s), the count of
                  kept cells on stderr, and every cell journalled once (none run twice).
  --part nscd     the same under non-smooth contact dynamics (solver.scheme = "nscd", rigid
                  blocks; docs/nscd.md): a 12-cell sweep and an IDA of the slender block under 3
                  records, each without mpirun (2 threads), under mpirun -n 1 (2 threads) and
                  under mpirun -n 2 (1 thread a rank): the same CSVs byte for byte once the
                  wall_s column is removed, and the same JSON in full precision (the contact
                  solver's record of every rank's runs included) once the walls, paths and
                  ranks are removed; then each cut and resumed under mpirun -n 2 (the sweep's
                  journal after 5 cells and half a line, the IDA's after its first record's
                  runs and half a line): the uninterrupted CSVs and JSON again, nothing
                  journalled twice.

Settings are the cheap ones of the unit tests (coarse tolerance, soft coarse arch, short
times): about 30 s of CPU for --part same, 10 s for --part resume, 5 s for --part nscd.
Usage: tests/python/mpi_ranks.py --bin build/voussoir --mpirun mpirun --work DIR --part same"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess

from checks import SOURCE, check, finish

# mpirun as root (CI) and with more ranks than free cores (2 shared cores).
MPI_FLAGS = ["--allow-run-as-root", "--oversubscribe"]

SWEEP = ["sweep", os.path.join(SOURCE, "cases", "block.toml"), "--set", "capacity.tolerance=0.05",
         "--param", "contact.friction=0.2,0.3,0.6,0.9", "--param", "model.width=0.3,0.5,0.7"]
# The Gilbert arch scaled to Rc = 1 m and softened as in tests/unit/test_stability_map.cpp:
# 10 cells collapse, 6 stand, as with --ke-time 0.3 --max-time 1.5 (at twice the cost).
STABILITY = ["stability", os.path.join(SOURCE, "cases", "gilbert_arch.toml"),
             "--set", "model.radius=1", "--set", "mesh.through_thickness=1",
             "--set", "material.young=4e7", "--param", "model.thickness_ratio=0.05,0.1,0.15,0.2",
             "--param", "contact.friction=0.2,0.4,0.6,0.8", "--ke-time", "0.15", "--max-time", "0.6"]
CURVE = ["pulse", os.path.join(SOURCE, "cases", "block.toml"), "--set", "mesh.size=0.5",
         "--set", "material.young=1e9", "--set", 'load.base.signal="windowed_sine"', "--curve",
         "--freqs", "2,3,4,5", "--lambda-star", "0.5", "--search", "bisect"]


IDA = ["ida", os.path.join(SOURCE, "cases", "block.toml"), "--set", "model.width=0.2",
       "--set", 'material.model="rigid"', "--set", "contact.normal_stiffness=1e10",
       "--set", "contact.shear_stiffness=1e10", "--lambda-star", "0.2"]


# Non-smooth contact dynamics of the rigid blocks (docs/nscd.md): the block's sweep (a capacity
# search a cell) and the slender block's IDA (a record's intensity search a cell).
NSCD = ["--set", 'material.model="rigid"', "--set", 'solver.scheme="nscd"']
NSCD_SWEEP = SWEEP + NSCD
NSCD_IDA = ["ida", os.path.join(SOURCE, "cases", "block.toml"), "--set", "model.width=0.2",
            "--lambda-star", "0.2"] + NSCD


def write_records(work):
    """Three 6 s two-column records (sums of sinusoids under an envelope, peak 0.3 g), as in
    tests/unit/test_ida.cpp; returns their paths joined by commas."""
    paths = []
    for k in range(3):
        freqs = (0.9, 1.7, 2.6, 3.3, 4.4, 5.8)
        a = []
        for i in range(601):
            t = 0.01 * i
            v = sum(math.sin(2 * math.pi * f * t + 1.3 * (k + 1) * (j + 1)) / math.sqrt(f)
                    for j, f in enumerate(freqs))
            a.append(v * min(1.0, t * t) * (math.exp(-1.5 * (t - 4.0)) if t > 4.0 else 1.0))
        peak = max(abs(v) for v in a)
        path = os.path.join(work, f"rec{k}.txt")
        with open(path, "w") as f:
            for i, v in enumerate(a):
                f.write(f"{0.01 * i:.2f}, {0.3 * v / peak:.9e}\n")
        paths.append(path)
    return ",".join(paths)


def run(cmd):
    """Runs a command; returns (exit status, stdout, stderr)."""
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def rows_without_wall(path):
    """The CSV's rows with the wall_s column left out."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows or "wall_s" not in rows[0]:
        return rows
    k = rows[0].index("wall_s")
    return [r[:k] + r[k + 1:] for r in rows]


# What a study's JSON may change with the ranks: walls, output paths and the ranks.
VARYING = {"wall_s", "capacity_wall_s", "csv", "runs_csv", "ranks"}


def json_results(path, varying=VARYING):
    """A study's JSON with the `varying` keys left out at every level."""
    def strip(v):
        if isinstance(v, dict):
            return {k: strip(x) for k, x in v.items() if k not in varying}
        if isinstance(v, list):
            return [strip(x) for x in v]
        return v
    with open(path) as f:
        return strip(json.load(f))


def study(a, name, args, ranks, extra=(), mpirun=None):
    """One run of a study, in one process of 2 threads (ranks 1) or under mpirun -n ranks with 1
    thread a rank (2 threads for one rank); mpirun: whether to start it by mpirun (by default
    when ranks > 1). Returns its paths and its (status, stdout, stderr)."""
    mpirun = ranks > 1 if mpirun is None else mpirun
    out = os.path.join(a.work, f"{name}_{ranks}" + ("_mpirun" if mpirun and ranks == 1 else ""))
    threads = "2" if ranks == 1 else "1"
    cmd = [a.bin] + args + ["--threads", threads, "--csv", out + ".csv", "--json", out + ".json"]
    cmd += list(extra)
    if mpirun:
        cmd = [a.mpirun] + MPI_FLAGS + ["-n", str(ranks)] + cmd
    return out, run(cmd)


def same(a):
    # A step budget that the 6 standing cells of the map exceed (they run to rest or to
    # --max-time; the collapsed ones stop at --ke-time): failed cells, reported in their rows
    # while the others run, exit status 1, in one process as under mpirun.
    failing = STABILITY + ["--max-steps", "20000"]
    ida = IDA + ["--records", write_records(a.work)]
    for name, args, expect_rc in (("sweep", SWEEP, 0), ("stability", STABILITY, 0),
                                  ("curve", CURVE, 0), ("ida", ida, 0), ("failing", failing, 1)):
        one, (rc1, _, err1) = study(a, name, args, 1)
        two, (rc2, out2, err2) = study(a, name, args, 2)
        check(rc1 == expect_rc, f"{name} in one process: exit {rc1}\n{err1[-2000:]}")
        check(rc2 == expect_rc, f"{name} under mpirun -n 2: exit {rc2}\n{err2[-2000:]}")
        if rc1 != expect_rc or rc2 != expect_rc:
            continue
        r1, r2 = rows_without_wall(one + ".csv"), rows_without_wall(two + ".csv")
        check(len(r1) > 1, f"{name}: the one-process CSV has no rows")
        check(r1 == r2, f"{name}: the CSVs differ (wall_s aside):\n{r1}\n{r2}")
        if name == "ida":
            runs1, runs2 = rows_without_wall(one + "_runs.csv"), rows_without_wall(two + "_runs.csv")
            check(len(runs1) > 3 and runs1 == runs2,
                  f"ida: the runs CSVs differ (wall_s aside):\n{runs1}\n{runs2}")
        j1, j2 = json.load(open(one + ".json")), json.load(open(two + ".json"))
        check(j1.get("ranks") == 1 and j2.get("ranks") == 2,
              f"{name}: JSON ranks {j1.get('ranks')} and {j2.get('ranks')}, expected 1 and 2")
        check("2 ranks" in err2, f"{name}: no dealing line on stderr:\n{err2[-2000:]}")
        # Rank 0 alone prints: one summary line.
        check(out2.count(" written to ") + out2.count("; curve ") + out2.count(", runs ") == 1,
              f"{name}: stdout under mpirun is not one rank's:\n{out2}")
    with open(os.path.join(a.work, "failing_2.csv"), newline="") as f:
        reasons = [(r["reason"], r["error"] != "") for r in csv.DictReader(f)]
    check(reasons.count(("error", True)) == 6 and len(reasons) == 16,
          f"failing map: not 6 failed cells of 16 with their errors: {reasons}")
    # The sweep's 12 cells and the map's 16.
    check(len(rows_without_wall(os.path.join(a.work, "sweep_1.csv"))) == 13, "sweep: not 12 cells")
    check(len(rows_without_wall(os.path.join(a.work, "stability_1.csv"))) == 17,
          "stability: not 16 cells")


def cell_records(journal):
    """The complete cell records of a journal (a line cut by a kill is not one)."""
    out = []
    for line in open(journal).read().splitlines()[1:]:
        try:
            out.append(json.loads(line))
        except json.JSONDecodeError:
            pass
    return out


def resume(a):
    journal = os.path.join(a.work, "sweep.journal")
    full, (rc, _, err) = study(a, "sweep_full", SWEEP, 2, ["--resume", journal])
    check(rc == 0, f"uninterrupted MPI sweep: exit {rc}\n{err[-2000:]}")
    if rc != 0:
        return
    lines = open(journal).read().splitlines()
    check(len(lines) == 13, f"the journal holds {len(lines) - 1} records, expected 12")
    kept = 5
    with open(journal, "w") as f:
        f.write("\n".join(lines[:1 + kept]) + "\n" + lines[1 + kept][: len(lines[1 + kept]) // 2])
    kept_cells = {json.loads(l)["cell"] for l in lines[1:1 + kept]}

    resumed, (rc, _, err) = study(a, "sweep_resumed", SWEEP, 2, ["--resume", journal])
    check(rc == 0, f"resumed MPI sweep: exit {rc}\n{err[-2000:]}")
    if rc != 0:
        return
    check(f"{kept} of 12 cells finished in the journal" in err,
          f"the resumed sweep does not say it kept {kept} cells:\n{err[-2000:]}")
    check(f"{12 - kept} cells dealt to 2 ranks" in err,
          f"the resumed sweep does not deal the {12 - kept} others:\n{err[-2000:]}")
    check(rows_without_wall(full + ".csv") == rows_without_wall(resumed + ".csv"),
          "the resumed CSV differs from the uninterrupted one (wall_s aside)")
    # Kept cells are not run again: their wall_s is the journalled one, and the journal holds
    # each cell once.
    with open(full + ".csv", newline="") as f:
        a_rows = list(csv.reader(f))
    with open(resumed + ".csv", newline="") as f:
        b_rows = list(csv.reader(f))
    wall = a_rows[0].index("wall_s")
    for c in kept_cells:
        check(a_rows[1 + c][wall] == b_rows[1 + c][wall], f"cell {c} was run again")
    cells = [r["cell"] for r in cell_records(journal)]
    check(sorted(cells) == list(range(12)), f"journal cells after the resume: {sorted(cells)}")


def nscd(a):
    """--part nscd (module comment)."""
    records = write_records(a.work)
    ida = NSCD_IDA + ["--records", records]
    for name, args in (("nscd_sweep", NSCD_SWEEP), ("nscd_ida", ida)):
        # Without mpirun (2 threads), under mpirun -n 1 (2 threads) and -n 2 (1 thread a rank).
        runs = []
        for ranks, mpirun in ((1, False), (1, True), (2, True)):
            out, (rc, _, err) = study(a, name, args, ranks, mpirun=mpirun)
            check(rc == 0, f"{name}, {ranks} ranks (mpirun: {mpirun}): exit {rc}\n{err[-2000:]}")
            if rc == 0:
                runs.append((ranks, out, err))
        if len(runs) != 3:
            continue
        tables = ["", "_runs"] if name == "nscd_ida" else [""]
        first = runs[0][1]
        for ranks, out, err in runs:
            for t in tables:
                r0, r1 = rows_without_wall(first + t + ".csv"), rows_without_wall(out + t + ".csv")
                check(len(r0) > 3 and r0 == r1,
                      f"{name}: {out}{t}.csv differs from {first}{t}.csv (wall_s aside):\n{r0}\n{r1}")
            # The JSON's numbers in full (the runs CSV rounds them), the contact solver's record
            # of every rank's runs included.
            check(json_results(first + ".json") == json_results(out + ".json"),
                  f"{name}: {out}.json differs from {first}.json (walls, paths, ranks aside):\n"
                  f"{json_results(first + '.json').get('solver')}\n"
                  f"{json_results(out + '.json').get('solver')}")
            j = json.load(open(out + ".json"))
            check(j.get("ranks") == ranks, f"{name}: JSON ranks {j.get('ranks')}, expected {ranks}")
            check(j.get("solver", {}).get("scheme") == "nscd",
                  f"{name}: the JSON's solver record is not nscd's: {j.get('solver')}")
        check("2 ranks" in runs[2][2], f"{name}: no dealing line on stderr:\n{runs[2][2][-2000:]}")
    check(len(rows_without_wall(os.path.join(a.work, "nscd_sweep_1.csv"))) == 13,
          "nscd sweep: not 12 cells")

    # Cut and resumed under mpirun -n 2: the sweep's journal after 5 cells and half a line, the
    # IDA's after the runs of its first finished record (a record's runs reach the journal
    # together under MPI: docs/mpi.md) and half a line.
    for name, args, count in (("nscd_sweep", NSCD_SWEEP, None), ("nscd_ida", ida, "record")):
        journal = os.path.join(a.work, name + ".journal")
        full, (rc, _, err) = study(a, name + "_full", args, 2, ["--resume", journal])
        check(rc == 0, f"{name}: uninterrupted MPI run: exit {rc}\n{err[-2000:]}")
        if rc != 0:
            continue
        lines = open(journal).read().splitlines()
        records = [json.loads(l) for l in lines[1:]]
        if count is None:
            kept = 5
        else:
            kept = sum(1 for r in records if r[count] == records[0][count])
        check(len(records) > kept, f"{name}: the journal holds {len(records)} records only")
        with open(journal, "w") as f:
            f.write("\n".join(lines[:1 + kept]) + "\n" + lines[1 + kept][: len(lines[1 + kept]) // 2])
        resumed, (rc, _, err) = study(a, name + "_resumed", args, 2, ["--resume", journal])
        check(rc == 0, f"{name}: resumed MPI run: exit {rc}\n{err[-2000:]}")
        if rc != 0:
            continue
        tables = ["", "_runs"] if name == "nscd_ida" else [""]
        for t in tables:
            check(rows_without_wall(full + t + ".csv") == rows_without_wall(resumed + t + ".csv"),
                  f"{name}: the resumed {t or 'main'} CSV differs from the uninterrupted one")
        # (The solver's record counts the runs made, not those taken from the journal.)
        resumed_varying = VARYING | {"solver"}
        check(json_results(full + ".json", resumed_varying) ==
              json_results(resumed + ".json", resumed_varying),
              f"{name}: the resumed JSON differs from the uninterrupted one (walls aside)")
        # Nothing journalled twice: each cell, each record's run at an intensity, once.
        def key(r):
            return r["cell"] if count is None else (r["record"], r["amplitude"])
        again = cell_records(journal)
        check(sorted(map(key, again)) == sorted(map(key, records)),
              f"{name}: the resumed journal's records differ from the uninterrupted one's: "
              f"{sorted(map(key, again))} against {sorted(map(key, records))}")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--mpirun", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--part", choices=["same", "resume", "nscd"], required=True)
    a = ap.parse_args()
    a.work = os.path.abspath(os.path.join(a.work, a.part))
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    {"same": same, "resume": resume, "nscd": nscd}[a.part](a)
    finish(f"mpi_ranks --part {a.part}")


if __name__ == "__main__":
    main()
