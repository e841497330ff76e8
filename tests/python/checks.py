"""Shared by the scripts of tests/python: where the sources are, and a check that records a
failure and goes on (the script exits non-zero at the end with finish())."""
import os
import sys

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL:", what)


def finish(name):
    if failures:
        sys.exit(f"{name}: {len(failures)} checks failed")
    print(f"{name}: all checks passed")
