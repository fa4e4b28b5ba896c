"""YAML reading with limits, for parameter and settings files.

A YAML document can be small on disk and huge in memory (nested aliases expand
exponentially) or deep enough to exhaust the recursion of a constructor. :func:`load_yaml`
refuses such files before building any Python object: it checks the size on disk, then
streams the parser's events counting the nesting depth and the number of values the document
holds with every alias expanded. Errors are :class:`YamlLimitError` (a ``ValueError``) whose
message names the file and, where known, the line; values are never echoed.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

__all__ = [
    "describe_kind",
    "MAX_BYTES",
    "MAX_DEPTH",
    "MAX_VALUES",
    "YamlLimitError",
    "field_path",
    "load_yaml",
    "to_number",
]

MAX_BYTES = 1 << 20
"""Largest file accepted [bytes] (1 MiB; a parameter file is a few hundred bytes)."""
MAX_DEPTH = 32
"""Deepest nesting of mappings and sequences accepted."""
MAX_VALUES = 100_000
"""Most values (scalars and collections) a document may hold with its aliases expanded."""


class YamlLimitError(ValueError):
    """A file that is not valid YAML or exceeds a limit (size, depth, expanded values)."""


def _where(path: Path, mark) -> str:
    return f"{path}:{mark.line + 1}" if mark is not None else str(path)


def _check_events(text: str, path: Path, max_depth: int, max_values: int) -> None:
    """Streams the parser's events: depth and alias-expanded size without building objects."""
    import yaml

    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    sizes: dict[str, int] = {}  # anchor -> number of values of the anchored node, expanded
    stack: list[tuple[str | None, int]] = []  # open collections: (anchor, count at start)
    count = 0
    for event in yaml.parse(text, Loader=loader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            count += 1
            stack.append((event.anchor, count - 1))
            if len(stack) > max_depth:
                raise YamlLimitError(
                    f"{_where(path, event.start_mark)}: nested deeper than {max_depth} levels")
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            anchor, start = stack.pop()
            if anchor is not None:
                sizes[anchor] = count - start
        elif isinstance(event, yaml.ScalarEvent):
            count += 1
            if event.anchor is not None:
                sizes[event.anchor] = 1
        elif isinstance(event, yaml.AliasEvent):
            count += sizes.get(event.anchor, 1)
        if count > max_values:
            raise YamlLimitError(
                f"{_where(path, getattr(event, 'start_mark', None))}: more than {max_values} "
                "values with its aliases (*name) expanded")


def load_yaml(path: str | Path, *, max_bytes: int = MAX_BYTES, max_depth: int = MAX_DEPTH,
              max_values: int = MAX_VALUES) -> Any:
    """The YAML document of ``path`` as Python objects (safe constructors only).

    Raises:
        OSError: the file cannot be opened (FileNotFoundError, PermissionError; filename set).
        YamlLimitError: a directory, larger than ``max_bytes``, not UTF-8 text,
            not valid YAML, nested deeper than ``max_depth`` or more than ``max_values`` values
            with the aliases expanded.
    """
    import yaml

    path = Path(path)
    try:
        size = path.stat().st_size
        if path.is_dir():
            raise YamlLimitError(f"{path}: is a directory")
        if size > max_bytes:
            raise YamlLimitError(f"{path}: {size} bytes; at most {max_bytes} bytes accepted")
        with path.open("rb") as f:
            raw = f.read(max_bytes + 1)
    except OSError as err:  # FileNotFoundError, PermissionError...: the file and the reason
        raise type(err)(err.errno, err.strerror or "cannot be read", str(path)) from None
    if len(raw) > max_bytes:  # grew while reading (a pipe or a special file)
        raise YamlLimitError(f"{path}: more than {max_bytes} bytes; at most {max_bytes} accepted")
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise YamlLimitError(f"{path}: UTF-16 text; save the file as UTF-8")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise YamlLimitError(f"{path}: not UTF-8 text (byte {err.start})") from None
    if "\x00" in text:
        raise YamlLimitError(f"{path}: binary data (NUL byte), not a YAML text file")
    try:
        _check_events(text, path, max_depth, max_values)
        loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
        return yaml.load(text, Loader=loader)  # noqa: S506 (safe loader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        problem = getattr(err, "problem", None) or "syntax error"
        raise YamlLimitError(f"{_where(path, mark)}: not valid YAML: {problem}") from None
    except RecursionError:  # not expected within max_depth; reported like a limit
        raise YamlLimitError(f"{path}: nested too deeply") from None


def describe_kind(value: Any) -> str:
    """'nothing (null)', 'a boolean', 'an integer', 'a number', 'text', 'a list', 'a mapping':
    what a YAML value is, for messages that must not echo the value."""
    if value is None:
        return "nothing (null)"
    for kind, text in ((bool, "a boolean"), (int, "an integer"), (float, "a number"), (str, "text"),
                       (list, "a list"), (dict, "a mapping")):
        if isinstance(value, kind):
            return text
    return f"a {type(value).__name__}"


def field_path(*parts: Any) -> str:
    """'contact.mu', 'observer.gain': the dotted path of a field (keys as text, truncated)."""
    out = []
    for p in parts:
        text = p if isinstance(p, str) else type(p).__name__ if not isinstance(p, int) else str(p)
        out.append(text if len(text) <= 40 else text[:37] + "...")
    return ".".join(out)


_INF_WORDS = {"inf": math.inf, ".inf": math.inf, "+inf": math.inf, "+.inf": math.inf,
              "infinity": math.inf, "-inf": -math.inf, "-.inf": -math.inf,
              "-infinity": -math.inf, "nan": math.nan, ".nan": math.nan}


def to_number(value: Any, where: str) -> float:
    """A float from a YAML/Python value (int, float, numeric text such as '1e-3' or 'inf',
    numpy scalars); ``ValueError`` naming ``where`` for booleans, None, collections, text that
    is not a number and integers too large for a float. The value itself is not echoed."""
    if hasattr(value, "item") and not isinstance(value, (list, dict, str)):
        try:
            value = value.item()  # numpy scalar (0-d)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: must be a number, not an array") from None
    if isinstance(value, bool):
        raise ValueError(f"{where}: must be a number, not a boolean (true/false)")
    if value is None:
        raise ValueError(f"{where}: has no value (must be a number)")
    if isinstance(value, int):
        try:
            return float(value)
        except OverflowError:
            raise ValueError(f"{where}: integer too large for a floating-point number") from None
    if isinstance(value, float):
        return value
    if isinstance(value, str):
        t = value.strip().lower()
        if t in _INF_WORDS:
            return _INF_WORDS[t]
        if len(t) > 64:
            raise ValueError(f"{where}: text of {len(value)} characters is not a number")
        try:
            return float(t)
        except ValueError:
            raise ValueError(f"{where}: text that is not a number") from None
    if hasattr(value, "__float__") and not isinstance(value, (list, dict, complex)):
        try:  # Decimal, Fraction, other real-number types
            return float(value)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"{where}: not convertible to a floating-point number") from None
    raise ValueError(f"{where}: must be a number, not {describe_kind(value)}")
