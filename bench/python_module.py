#!/usr/bin/python3
"""The Python module's cost over the program (docs/guide/python.md, "What it costs"): the wall
of `voussoir.capacity` on a deck against `build/voussoir capacity` on the same deck, in
alternated pairs (median of each and of the pairs' ratios); and how soon Ctrl-C ends
`capacity` on church B (SIGINT after --after seconds; the time until KeyboardInterrupt).

    bench/python_module.py [--build build] [--deck cases/circular_arch.toml] [--runs 5]
"""
import argparse
import os
import signal
import statistics
import subprocess
import sys
import threading
import time

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--deck", default=os.path.join(ROOT, "cases", "circular_arch.toml"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--after", type=float, default=3.0, help="seconds before the Ctrl-C")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(os.path.abspath(a.build), "python"))
    import voussoir

    program = os.path.join(os.path.abspath(a.build), "voussoir")
    walls_program, walls_module, ratios = [], [], []
    for _ in range(a.runs):
        t0 = time.perf_counter()
        subprocess.run([program, "capacity", a.deck, "-q"], check=True, stdout=subprocess.DEVNULL)
        walls_program.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        voussoir.capacity(a.deck, quiet=True)
        walls_module.append(time.perf_counter() - t0)
        ratios.append(walls_module[-1] / walls_program[-1])
    print(f"capacity {os.path.relpath(a.deck, ROOT)}: program {statistics.median(walls_program):.3f} s, "
          f"module {statistics.median(walls_module):.3f} s (medians of {a.runs}); "
          f"module / program {statistics.median(ratios):.4f} (median of the pairs' ratios)")

    church = os.path.join(ROOT, "cases", "church_b.toml")
    sent = {}

    def interrupt():
        sent["at"] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(a.after, interrupt)
    timer.start()
    try:
        voussoir.capacity(church, quiet=True)
        print("church_b: the search ended before the Ctrl-C; raise --after")
    except KeyboardInterrupt:
        print(f"church_b capacity: KeyboardInterrupt {time.perf_counter() - sent['at']:.3f} s "
              f"after SIGINT (sent {a.after:g} s into the search)")
    print(f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
