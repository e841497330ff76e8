"""The Python module `voussoir` against the program (docs/guide/python.md).

Every function's dict has the keys and values of its command's --json on the same deck and
options (wall times aside); bad input raises DeckError naming it; a failure raises RunError;
Ctrl-C stops a long call; progress lines reach the callable. Run by ctest (`python`) with
PYTHONPATH=build/python and VOUSSOIR_BIN, VOUSSOIR_ROOT set:

    VOUSSOIR_BIN=build/voussoir VOUSSOIR_ROOT=. PYTHONPATH=build/python \
        /usr/bin/python3 -m pytest -q tests/python/test_module.py
"""
import json
import os
import signal
import subprocess
import sys

import numpy
import pytest

import voussoir

BIN = os.environ["VOUSSOIR_BIN"]
ROOT = os.environ["VOUSSOIR_ROOT"]


def case(name):
    return os.path.join(ROOT, "cases", name + ".toml")


# The slender rigid block of the IDA tests: 0.2 x 1 m on stiff joints, no bounce.
BLOCK_SET = {"model.width": 0.2, "material.model": "rigid", "contact.normal_stiffness": 1e10,
             "contact.shear_stiffness": 1e10, "contact.restitution": 0}


def without_walls(value):
    """JSON values without what the machine's speed sets: the wall times, and the count of
    capacity trials run ahead on idle cores."""
    if isinstance(value, dict):
        return {k: without_walls(v) for k, v in value.items() if "wall" not in k and k != "ahead"}
    if isinstance(value, list):
        return [without_walls(v) for v in value]
    return value


def as_json(value):
    """A module result back to JSON's types (numpy arrays to lists)."""
    if isinstance(value, dict):
        return {k: as_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [as_json(v) for v in value]
    if isinstance(value, numpy.ndarray) and value.dtype.names:
        return [dict(zip(value.dtype.names, row)) for row in value.tolist()]
    if isinstance(value, numpy.ndarray):
        return value.tolist()
    return value


def program(args, tmp_path):
    out = tmp_path / "program.json"
    quiet = [] if args[0] == "synth" else ["-q"]
    p = subprocess.run([BIN] + args + ["--json", str(out)] + quiet, capture_output=True,
                       text=True)
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text())


def sets_of(overrides):
    args = []
    for key, value in overrides.items():
        args += ["--set", f"{key}={voussoir._toml(value)}"]
    return args


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """Two short artificial records (synth, written by the module)."""
    folder = tmp_path_factory.mktemp("records")
    voussoir.synth(ag=0.25, count=2, duration=5, output=str(folder), no_plot=True)
    found = sorted(str(folder / f) for f in os.listdir(folder) if f.endswith(".AT2"))
    assert len(found) == 2
    return found


# (command, deck, deck overrides, options as the module takes them, the same on the command line)
def cases(tmp, records):
    block = case("block")
    nscd = {"solver.scheme": "nscd"}
    return [
        ("check", case("circular_arch"), {}, {}, []),
        ("run", case("circular_arch"), {"solver.end_time": 0.05}, {}, []),
        ("capacity", case("circular_arch"), {}, {"threads": 2}, ["--threads", "2"]),
        ("pushover", case("circular_arch"), nscd, {"stop_at": 0.9, "csv": f"{tmp}/po.csv"},
         ["--stop-at", "0.9", "--csv", f"{tmp}/po.csv"]),
        ("limit", case("circular_arch"), {}, {"thrust": "min"}, ["--thrust", "min"]),
        ("spread", case("circular_arch"), nscd, {"tolerance": 0.2, "csv": f"{tmp}/spread.csv"},
         ["--tolerance", "0.2", "--csv", f"{tmp}/spread.csv"]),
        ("pulse", case("scaled_arch"), {**nscd, "load.base.amplitude": 0.4}, {}, []),
        ("ida", block, {**BLOCK_SET, **nscd},
         {"records": records, "lambda_star": 0.2, "threads": 1, "csv": f"{tmp}/ida.csv"},
         ["--records", ",".join(records), "--lambda-star", "0.2", "--threads", "1",
          "--csv", f"{tmp}/ida.csv"]),
        ("sweep", case("circular_arch"), nscd,
         {"param": {"contact.friction": [0.5, 0.6]}, "csv": f"{tmp}/sweep.csv"},
         ["--param", "contact.friction=0.5,0.6", "--csv", f"{tmp}/sweep.csv"]),
        ("stability", case("gilbert_arch"), {"material.model": "rigid", **nscd},
         {"param": {"contact.friction": [0.3, 0.6]}, "csv": f"{tmp}/map.csv", "max_time": 0.5,
          "ke_time": 0.1},
         ["--param", "contact.friction=0.3,0.6", "--csv", f"{tmp}/map.csv", "--max-time", "0.5",
          "--ke-time", "0.1"]),
        ("synth", None, {}, {"ag": 0.2, "count": 2, "duration": 5, "output": f"{tmp}/synth",
                             "no_plot": True},
         ["--ag", "0.2", "--count", "2", "--duration", "5", "--output", f"{tmp}/synth",
          "--no-plot"]),
    ]


COMMANDS = ["check", "run", "capacity", "pushover", "limit", "spread", "pulse", "ida", "sweep",
            "stability", "synth"]


def test_every_command_has_a_function():
    assert sorted(c["name"] for c in voussoir.COMMANDS) == sorted(COMMANDS)
    for name in COMMANDS:
        assert callable(getattr(voussoir, name))
        assert getattr(voussoir, name).__doc__


@pytest.mark.parametrize("name", COMMANDS)
def test_same_keys_and_values_as_the_command(name, tmp_path, records):
    command, deck, overrides, options, arguments = next(
        c for c in cases(tmp_path, records) if c[0] == name)
    if deck is None:
        expected = program([command] + arguments, tmp_path)
        got = getattr(voussoir, command)(**options)
    else:
        expected = program([command, deck] + sets_of(overrides) + arguments, tmp_path)
        got = getattr(voussoir, command)(voussoir.Deck(deck, set=overrides), quiet=True, **options)
    assert "solver" not in expected or expected["solver"] == got["solver"]
    assert without_walls(as_json(got)) == without_walls(expected)


def test_capacity_of_the_demo_arch_with_curves_as_arrays():
    deck = voussoir.Deck(case("circular_arch"))
    result = voussoir.capacity(deck, quiet=True)
    assert round(result["lambda_star"], 4) == 0.2934
    assert isinstance(result["bracket"], numpy.ndarray) and result["bracket"].shape == (2,)
    assert isinstance(result["runs"], list)


def test_import_from_another_folder_with_debian_python(tmp_path):
    code = ("import voussoir; d = voussoir.Deck(%r); r = voussoir.limit(d, quiet=True); "
            "print('lambda_la', r['lambda_la'])" % case("circular_arch"))
    p = subprocess.run(["/usr/bin/python3", "-c", code], cwd=tmp_path, capture_output=True,
                       text=True, env={**os.environ, "PYTHONPATH": os.path.dirname(
                           os.path.dirname(voussoir.__file__))})
    assert p.returncode == 0, p.stderr
    assert 0.2 < float(p.stdout.split("lambda_la ")[-1]) < 0.4


def test_deck_as_text_takes_files_from_the_current_folder(tmp_path, monkeypatch):
    text = open(case("circular_arch")).read()
    from_text = voussoir.check(voussoir.Deck(text), quiet=True)
    from_file = voussoir.check(voussoir.Deck(case("circular_arch")), quiet=True)
    assert from_text["blocks"] == from_file["blocks"]
    monkeypatch.chdir(ROOT)
    gmsh = voussoir.Deck(open(case("wall")).read().replace('"wall.msh"', '"cases/wall.msh"'))
    assert voussoir.check(gmsh, quiet=True)["blocks"] > 1


@pytest.mark.parametrize("make, says", [
    (lambda: voussoir.Deck(case("circular_arch"), set={"contact.fricton": 0.5}), "contact.fricton"),
    (lambda: voussoir.Deck(case("circular_arch"), set={"contact.friction": -1}), "contact.friction"),
    (lambda: voussoir.Deck("/no/such/deck.toml"), "/no/such/deck.toml"),
    (lambda: voussoir.capacity(case("circular_arch"), tolerence=0.1), "tolerence"),
    (lambda: voussoir.capacity(case("circular_arch"), points="many"), "--points"),
    (lambda: voussoir.capacity(case("circular_arch"), set={"solver.theta": 2}), "solver.theta"),
])
def test_bad_input_raises_deck_error_naming_it(make, says):
    with pytest.raises(voussoir.DeckError) as e:
        make()
    assert isinstance(e.value, ValueError)
    assert says in str(e.value)


def test_a_failure_during_a_run_raises_run_error():
    deck = voussoir.Deck(case("circular_arch"), set={"solver.end_time": 1.0})
    with pytest.raises(voussoir.RunError) as e:
        voussoir.run(deck, max_steps=10, quiet=True)
    assert "10" in str(e.value)


def test_progress_lines_reach_the_callable():
    lines = []
    voussoir.capacity(case("circular_arch"), progress=lines.append)
    assert any("lambda =" in line for line in lines)


def test_ctrl_c_stops_a_long_call_and_the_next_call_runs():
    # Ctrl-C as soon as the church's capacity search reports: the call ends with
    # KeyboardInterrupt long before its search could.
    def interrupt(line):
        os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        voussoir.capacity(case("church_b"), progress=interrupt)
    assert voussoir.limit(case("circular_arch"), quiet=True)["lambda_la"] > 0


def test_foreign_interpreter_without_numpy_is_told_which_to_use(tmp_path):
    # An interpreter that cannot import numpy (here: numpy hidden) gets a message naming
    # Debian's Python.
    hide = tmp_path / "numpy.py"
    hide.write_text("raise ImportError('no numpy here')\n")
    path = os.pathsep.join([str(tmp_path), os.path.dirname(os.path.dirname(voussoir.__file__))])
    p = subprocess.run([sys.executable, "-c", "import voussoir"], capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": path})
    assert p.returncode != 0
    assert "/usr/bin/python3" in p.stderr


def test_the_reference_page_is_the_module_s(tmp_path):
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    import importlib.machinery
    import importlib.util
    loader = importlib.machinery.SourceFileLoader(
        "reference_python", os.path.join(ROOT, "scripts", "reference_python"))
    spec = importlib.util.spec_from_loader("reference_python", loader)
    reference = importlib.util.module_from_spec(spec)
    loader.exec_module(reference)
    committed = open(os.path.join(ROOT, "docs", "reference", "python.md")).read()
    assert reference.page(voussoir) == committed, "run scripts/reference_python"
