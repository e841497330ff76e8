#!/usr/bin/python3
"""Reads a run's .xdmf and .h5 as a user's script would (xml.etree, h5py) and checks what
ParaView and pandas users rely on (docs/reference/output.md):
  - every grid of the temporal collection has a Time value, the times increase;
  - every data item names an HDF5 dataset that resolves against the .xdmf's folder (read
    from another working directory) and has the declared dimensions;
  - point vectors have 3 components (z = 0); stress is named scalars, never a Vector;
  - displacement = position - reference (/mesh/nodes), on every snapshot;
  - the largest free-node displacement of the last snapshot (at the end of the run) is the
    JSON max_displacement.
Usage: tests/python/xdmf_h5.py --bin build/voussoir --work DIR   (ctest: xdmf_h5)"""
import argparse
import json
import os
import shutil
import subprocess
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from checks import SOURCE, check, finish


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    work = os.path.abspath(a.work)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(work, "elsewhere"))
    out = os.path.join(work, "out", "run.h5")
    summary = os.path.join(work, "run.json")
    # The block slides (lambda 0.3 > mu 0.2): displacements well above round-off.
    end_time = 0.05
    cmd = [a.bin, "run", os.path.join(SOURCE, "cases", "block.toml"), "--set", "load.lambda=0.3",
           "--set", "contact.friction=0.2", "--set", f"solver.end_time={end_time}", "--set",
           "output.every=0.01", "-o", out, "--json", summary, "-q"]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    run = json.load(open(summary))
    max_displacement, dt = run["max_displacement"], run["dt"]
    xdmf = os.path.join(work, "out", "run.xdmf")

    # Everything below from another folder: paths must resolve against the .xdmf's.
    os.chdir(os.path.join(work, "elsewhere"))
    base = os.path.dirname(xdmf)
    root = ET.parse(xdmf).getroot()
    files = {}

    def dataset(item):
        name, path = item.text.strip().split(":", 1)
        check(not os.path.isabs(name), f"data item names {name}: a relative name moves with the files")
        fname = os.path.join(base, name)
        check(os.path.exists(fname), f"{item.text.strip()} does not resolve from the .xdmf's folder")
        f = files.setdefault(fname, h5py.File(fname, "r"))
        d = f[path][()]
        dims = tuple(int(x) for x in item.get("Dimensions").split())
        check(d.shape == dims, f"{path}: shape {d.shape}, declared {dims}")
        return d

    collection = root.find("./Domain/Grid")
    check(collection.get("CollectionType") == "Temporal", "a temporal collection")
    grids = collection.findall("Grid")
    check(len(grids) >= 5, f"{len(grids)} snapshots")
    times = []
    last = None
    for g in grids:
        t = g.find("Time")
        check(t is not None, f"grid {g.get('Name')} has a Time value")
        times.append(float(t.get("Value")))
        reference = dataset(g.find("Geometry/DataItem"))
        attrs = {}
        for at in g.findall("Attribute"):
            d = dataset(at.find("DataItem"))
            attrs[at.get("Name")] = d
            if at.get("AttributeType") == "Vector":
                check(d.ndim == 2 and d.shape[1] == 3, f"{at.get('Name')}: 3 components")
                check(np.all(d[:, 2] == 0.0), f"{at.get('Name')}: z = 0")
            check(not (at.get("Name").startswith("stress") and at.get("AttributeType") != "Scalar"),
                  f"{at.get('Name')} is a named scalar")
        for name in ("displacement", "velocity", "stress_xx", "stress_yy", "stress_xy",
                     "stress_1", "stress_2", "block"):
            check(name in attrs, f"grid {g.get('Name')} has {name}")
        # displacement = position - reference, exactly (both from the same doubles).
        group = g.find("Attribute[@Name='displacement']/DataItem").text.strip().split(":", 1)[1]
        group = group.rsplit("/", 1)[0]
        f = next(iter(files.values()))
        position = f[group + "/position"][()]
        check(np.array_equal(attrs["displacement"][:, :2], position - reference),
              f"{group}: displacement = position - reference")
        check(np.all(attrs["stress_1"] >= attrs["stress_2"]), "stress_1 >= stress_2")
        last = attrs
    check(all(b > a for a, b in zip(times, times[1:])), f"times increase: {times}")
    # The run stops at the first step at or past end_time; its last snapshot is that state.
    check(abs(times[-1] - end_time) <= dt, f"the last snapshot is at the end ({times[-1]})")
    f = next(iter(files.values()))
    fixed = f["/mesh/fixed"][()]
    free = fixed[f["/mesh/node_block"][()]] == 0
    d = last["displacement"]
    largest = float(np.max(np.hypot(d[free, 0], d[free, 1])))
    check(largest > 1e-6, f"the block moved ({largest} m)")
    check(abs(largest - max_displacement) <= 1e-12 * max(largest, 1e-300),
          f"largest displacement {largest!r} = JSON max_displacement {max_displacement!r}")
    print(f"{len(grids)} snapshots, times {times[0]}..{times[-1]} s, max displacement "
          f"{largest:.6g} m (JSON {max_displacement:.6g} m)")
    finish("xdmf_h5")


if __name__ == "__main__":
    main()
