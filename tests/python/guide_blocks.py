#!/usr/bin/python3
"""Runs the command blocks of docs/guide/ that are marked for the test, and fails when one no
longer works (ctest `guide`, default suite).

A block is marked by an HTML comment on the line before its fence:

    <!-- guide-test -->            run it
    <!-- guide-test needs=X -->    run it only when X is there: a program on PATH (gmsh,
                                   mpirun), or a python module for /usr/bin/python3 (py:pandas)

followed by a ```sh fence, or a ```python fence (run by /usr/bin/python3, with the Python module
of the program's build, build/python, first on its path). The blocks of one page run in order,
the shell's each with `bash -e -o pipefail`, in one scratch folder per page that holds `cases`,
`scripts`, `tests` and `docs` of the source tree and `build/voussoir` (the program under test),
so the commands run as written from the repository root and write only to the scratch folder
(`out/`). Pass: exit status 0 within the timeout. Unmarked blocks (the slow ones) are shown to
users but not run here.

    tests/python/guide_blocks.py --bin build/voussoir [--root .] [--work DIR] [--only PAGE]
"""
import argparse
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import time

MARK = re.compile(r"^<!--\s*guide-test(?P<opts>[^>]*)-->\s*$")


def blocks_of(path):
    """(line, needs, language, text) of every marked ```sh or ```python block of a page."""
    lines = open(path).read().splitlines()
    out = []
    i = 0
    while i < len(lines):
        m = MARK.match(lines[i].strip())
        if not m:
            i += 1
            continue
        needs = [w[len("needs="):] for w in m.group("opts").split() if w.startswith("needs=")]
        j = i + 1
        while j < len(lines) and not lines[j].strip():
            j += 1
        language = lines[j][3:].strip() if j < len(lines) else ""
        if not lines[j].startswith("```") or language not in ("sh", "python"):
            raise SystemExit(f"{path}:{i + 1}: guide-test mark not followed by a ```sh or "
                             "```python block")
        k = j + 1
        while k < len(lines) and not lines[k].startswith("```"):
            k += 1
        out.append((j + 1, needs, language, "\n".join(lines[j + 1:k]) + "\n"))
        i = k + 1
    return out


def missing(needs):
    for n in needs:
        if n.startswith("py:"):
            probe = subprocess.run(["/usr/bin/python3", "-c", f"import {n[3:]}"],
                                   capture_output=True)
            if probe.returncode != 0:
                return n
        elif shutil.which(n) is None:
            return n
    return None


def scratch(work, page, root, binary):
    d = os.path.join(work, os.path.splitext(page)[0])
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(os.path.join(d, "build"))
    for name in ("cases", "scripts", "tests", "docs"):
        os.symlink(os.path.join(root, name), os.path.join(d, name))
    os.symlink(os.path.abspath(binary), os.path.join(d, "build", "voussoir"))
    return d


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True, help="the voussoir program")
    ap.add_argument("--root", default=os.path.normpath(os.path.join(here, "..", "..")))
    ap.add_argument("--work", default="/tmp/voussoir_guide")
    ap.add_argument("--only", default="", help="run only pages whose name contains this")
    ap.add_argument("--timeout", type=float, default=120.0, help="seconds per block")
    a = ap.parse_args()
    root = os.path.abspath(a.root)
    guide = os.path.join(root, "docs", "guide")
    env = dict(os.environ)
    env["PATH"] = "/usr/bin:/bin:" + env.get("PATH", "")   # Debian's python3 with numpy, h5py
    env["VOUSSOIR_BINARY"] = os.path.abspath(a.bin)
    env["MPLBACKEND"] = "Agg"
    module = os.path.join(os.path.dirname(os.path.abspath(a.bin)), "python")
    env["PYTHONPATH"] = module + os.pathsep + env.get("PYTHONPATH", "")
    failed, ran, skipped = [], 0, 0
    for page in sorted(os.listdir(guide)):
        if not page.endswith(".md") or a.only not in page:
            continue
        blocks = blocks_of(os.path.join(guide, page))
        if not blocks:
            continue
        d = scratch(a.work, page, root, a.bin)
        for line, needs, language, text in blocks:
            where = f"docs/guide/{page}:{line}"
            lack = missing(needs)
            if lack:
                print(f"skip  {where} (no {lack})")
                skipped += 1
                continue
            t0 = time.time()
            try:
                run = (["bash", "-e", "-o", "pipefail", "-c", text] if language == "sh"
                       else ["/usr/bin/python3", "-c", text])
                p = subprocess.run(run, cwd=d, env=env, capture_output=True, text=True,
                                   timeout=a.timeout)
                code, out = p.returncode, p.stdout + p.stderr
            except subprocess.TimeoutExpired as e:
                code, out = "timeout", f"over {a.timeout:.0f} s"
            ran += 1
            dt = time.time() - t0
            if code == 0:
                print(f"ok    {where} ({dt:.1f} s)")
            else:
                print(f"FAIL  {where} ({dt:.1f} s): exit {code}\n{text}---\n{out[-3000:]}")
                failed.append(where)
    print(f"{ran} blocks run, {skipped} skipped, {len(failed)} failed")
    if ran == 0:
        print("no marked block found under docs/guide/")
        return 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
