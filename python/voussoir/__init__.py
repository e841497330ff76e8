"""voussoir: collapse capacity of dry-joint masonry arches, from Python.

The engine of the voussoir program in this process: one function per command (check, run,
capacity, pushover, limit, spread, pulse, ida, sweep, stability, synth), taking a Deck and the
command's options as keyword arguments and returning the dict that the command's --json writes,
with its curves and histories as numpy arrays. The guide: docs/guide/python.md; every function
and option: docs/reference/python.md.

    import voussoir
    deck = voussoir.Deck("cases/circular_arch.toml", set={"contact.friction": 0.5})
    print(voussoir.capacity(deck)["lambda_star"])

Bad input raises DeckError (a ValueError) with the program's message; a failure during a run
raises RunError; Ctrl-C stops a long call within a step and raises KeyboardInterrupt.
"""

import json
import os
import queue
import sys
import tempfile
import threading
import tomllib

_DEBIAN_PYTHON = "/usr/bin/python3"


def _foreign(what):
    return ImportError(
        f"voussoir: {what}. The module is built for Debian's Python, {_DEBIAN_PYTHON} "
        f"(Python 3.{sys.version_info.minor} here, running {sys.executable}): run your script "
        f"with {_DEBIAN_PYTHON}, where numpy, matplotlib and h5py come from Debian "
        "(scripts/install-deps installs them; docs/guide/python.md)")


try:
    import numpy
except ImportError as e:
    raise _foreign("numpy cannot be imported") from e
try:
    from . import _voussoir
except ImportError as e:
    raise _foreign(f"its engine cannot be loaded ({e})") from e

DeckError = _voussoir.DeckError
RunError = _voussoir.RunError
DeckError.__module__ = RunError.__module__ = __name__
__version__ = _voussoir.version

# Deck keys whose relative file names the program takes from the deck's folder; a deck given as
# text has none, so they are taken from the current folder, as `--set` takes them.
_FILE_KEYS = (("model", "file"), ("load", "base", "file"))


def _toml(value):
    """A Python value as the TOML literal of a --set override."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, (str, os.PathLike)):
        return json.dumps(os.fspath(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    raise DeckError(f"set: {value!r} ({type(value).__name__}) is not a deck value "
                    "(a number, a string, a bool, or a list or table of them)")


def _overrides(set_):
    if set_ is None:
        return []
    if isinstance(set_, dict):
        return [f"{k}={_toml(v)}" for k, v in set_.items()]
    if isinstance(set_, str):
        return [set_]
    return [str(s) for s in set_]


class Deck:
    """A deck: a TOML file (its path) or TOML text, and overrides of its keys.

    Deck(path_or_text, set={"contact.friction": 0.5}) reads the deck and checks every key as
    the program does (DeckError names a missing file, an unknown key or a bad value). `set`
    takes a dict of dotted keys to Python values, or the program's "KEY=VALUE" strings.
    Relative file names in a file deck are taken from its folder; in a text deck, from the
    current folder.
    """

    def __init__(self, source, set=None):  # noqa: A002 (the program's option name)
        source = os.fspath(source)
        self.sets = _overrides(set)
        self._folder = None
        if "\n" in source or "=" in source:
            self.text = source
            try:
                table = tomllib.loads(source)
            except tomllib.TOMLDecodeError as e:
                raise DeckError(f"deck text: TOML syntax error: {e}") from None
            given = [s.split("=", 1)[0].strip() for s in self.sets]
            for path in _FILE_KEYS:
                node = table
                for part in path:
                    node = node.get(part) if isinstance(node, dict) else None
                key = ".".join(path)
                if isinstance(node, str) and not os.path.isabs(node) and key not in given:
                    self.sets.insert(0, f"{key}={json.dumps(os.path.abspath(node))}")
            self._folder = tempfile.TemporaryDirectory(prefix="voussoir-deck-")
            self.path = os.path.join(self._folder.name, "deck.toml")
            with open(self.path, "w") as f:
                f.write(source)
        else:
            self.text = None
            self.path = os.path.abspath(source)
        _voussoir.load_deck(self.path, self.sets)

    def with_set(self, set=None):  # noqa: A002
        """A copy of this deck with more overrides (they come after this deck's)."""
        deck = Deck.__new__(Deck)
        deck.text, deck.path, deck._folder = self.text, self.path, self._folder
        deck.sets = self.sets + _overrides(set)
        _voussoir.load_deck(deck.path, deck.sets)
        return deck

    def check(self, **options):
        """`voussoir check`: the model summary (see check())."""
        return check(self, **options)

    def __repr__(self):
        what = self.path if self.text is None else "<text>"
        return f"Deck({what!r}, set={self.sets!r})"


def _number_list(values):
    return bool(values) and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def _records(rows):
    """A list of dicts of numbers under the same keys (a curve, a history) as a numpy record
    array: curve["displacement"] is a column, curve[0] a point; None when it is not one."""
    if not rows or not all(isinstance(r, dict) for r in rows):
        return None
    keys = list(rows[0])
    if not keys or not all(list(r) == keys and _number_list(list(r.values())) for r in rows):
        return None
    dtype = [(k, numpy.asarray([r[k] for r in rows]).dtype) for k in keys]
    return numpy.array([tuple(r[k] for k in keys) for r in rows], dtype=dtype)


def _arrays(value):
    """JSON values with their lists of numbers, lists of equal rows of numbers and lists of
    numeric records as numpy arrays."""
    if isinstance(value, dict):
        return {k: _arrays(v) for k, v in value.items()}
    if isinstance(value, list):
        if _number_list(value):
            return numpy.asarray(value)
        if (value and all(isinstance(v, list) and _number_list(v) for v in value)
                and len({len(v) for v in value}) == 1):
            return numpy.asarray(value)
        records = _records(value)
        if records is not None:
            return records
        return [_arrays(v) for v in value]
    return value


def _argument(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    return os.fspath(value) if isinstance(value, os.PathLike) else str(value)


def _option_args(command, options):
    """The command's options, given as keyword arguments, as the program's arguments."""
    known = {o["name"].replace("-", "_"): o for o in command["options"]}
    args = []
    for key, value in options.items():
        spec = known.get(key)
        if spec is None:
            names = ", ".join(sorted(known))
            raise DeckError(f"{command['name']}: no option {key!r} (its options: {names})")
        flag = "--" + spec["name"]
        if value is None or (spec["flag"] and value is False):
            continue
        if spec["flag"]:
            if value is not True:
                raise DeckError(f"{command['name']}: {key}={value!r}: a switch takes True or False")
            args.append(flag)
        elif isinstance(value, dict):
            for k, v in value.items():
                v = ",".join(_argument(x) for x in v) if isinstance(v, (list, tuple)) else v
                args += [flag, f"{k}={_argument(v)}"]
        elif isinstance(value, (list, tuple)):
            if spec["many"]:
                args += [flag] + [_argument(v) for v in value]
            else:
                args += [flag, ",".join(_argument(v) for v in value)]
        else:
            args += [flag, _argument(value)]
    return args


class _StderrLines:
    """While a call runs: the program's lines on standard error, handed to `progress`."""

    def __init__(self, progress):
        self.progress = progress
        sys.stderr.flush()
        self.saved = os.dup(2)
        read, write = os.pipe()
        os.dup2(write, 2)
        os.close(write)
        self.lines = queue.SimpleQueue()
        self.reader = threading.Thread(target=self._read, args=(read,), daemon=True)
        self.reader.start()

    def _read(self, fd):
        pending = b""
        while chunk := os.read(fd, 65536):
            parts = chunk.replace(b"\r", b"\n").split(b"\n")
            parts[0] = pending + parts[0]
            pending = parts.pop()
            for p in parts:
                if p.strip():
                    self.lines.put(p.decode(errors="replace"))
        if pending.strip():
            self.lines.put(pending.decode(errors="replace"))
        os.close(fd)

    def dispatch(self):
        while True:
            try:
                line = self.lines.get_nowait()
            except queue.Empty:
                return
            self.progress(line)

    def close(self):
        os.dup2(self.saved, 2)  # closes the pipe's last writer: the reader sees its end
        os.close(self.saved)
        self.reader.join()


def _run(args, progress, summary):
    """Runs the program's arguments in a worker thread (the engine releases the GIL) while this
    thread waits, hands progress lines over and answers Ctrl-C by stopping the engine."""
    box = {}

    def work():
        try:
            box["status"] = _voussoir.run_command(args, summary)
        except BaseException as e:  # handed to the caller's thread
            box["error"] = e

    lines = _StderrLines(progress) if progress is not None else None
    worker = threading.Thread(target=work, name="voussoir " + args[0], daemon=True)
    try:
        worker.start()
        try:
            while worker.is_alive():
                worker.join(0.05)
                if lines is not None:
                    lines.dispatch()
        except BaseException:  # Ctrl-C, or progress raised: stop the engine, then re-raise
            _voussoir.request_stop()
            worker.join()
            _voussoir.clear_stop()
            raise
    finally:
        if lines is not None:
            lines.close()
            lines.dispatch()
    if "error" in box:
        raise box["error"]
    return box["status"]


def _call(command, deck, options):
    progress = options.pop("progress", None)
    summary = options.pop("summary", False)
    set_ = options.pop("set", None)
    args = [command["name"]]
    if command["deck"]:
        if deck is None:
            raise DeckError(f"{command['name']}: a deck is needed (voussoir.Deck or a path)")
        if not isinstance(deck, Deck):
            deck = Deck(deck)
        args.append(deck.path)
        for s in deck.sets + _overrides(set_):
            args += ["--set", s]
    elif deck is not None or set_ is not None:
        raise DeckError(f"{command['name']}: takes no deck")
    with tempfile.TemporaryDirectory(prefix="voussoir-") as folder:
        json_path = options.pop("json", None) or os.path.join(folder, "summary.json")
        args += _option_args(command, options) + ["--json", os.fspath(json_path)]
        status = _run(args, progress, summary)
        result = None
        if os.path.exists(json_path):
            with open(json_path) as f:
                result = _arrays(json.load(f))
    if status != 0:
        error = RunError(f"{command['name']} ended with exit status {status} "
                         "(its message is on standard error)")
        error.result = result
        raise error
    return result


def _make(command):
    name = command["name"]

    if command["deck"]:
        def function(deck, **options):
            return _call(command, deck, dict(options))
        signature = f"{name}(deck, **options)"
    else:
        def function(**options):
            return _call(command, None, dict(options))
        signature = f"{name}(**options)"
    lines = [f"{signature}: {command['help']}.", "",
             "Returns the dict of `voussoir " + name + " --json`. Options (keyword arguments;"
             " progress=callable receives the progress lines; summary=True prints the"
             " program's summary; set= adds deck overrides):"]
    for o in command["options"]:
        if o["name"] == "json":
            continue
        default = f" (default {o['default']})" if o["default"] else ""
        lines.append(f"  {o['name'].replace('-', '_')}: {o['help']}{default}")
    function.__name__ = function.__qualname__ = name
    function.__doc__ = "\n".join(lines)
    return function


COMMANDS = [c for c in _voussoir.commands() if c["name"] != "keys"]
for _command in COMMANDS:
    globals()[_command["name"]] = _make(_command)
del _command

__all__ = ["Deck", "DeckError", "RunError", "COMMANDS"] + [c["name"] for c in COMMANDS]
