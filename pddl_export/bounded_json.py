"""Reading the JSON files the tools read: bounded in size, depth and numbers, and checked against a schema.

Every JSON file a command reads (problems, goal files, rules.json, outcomes.json, benchmark row logs,
a run's result files, manifests, pipeline records) goes through `read_json_file`, so a hostile or
mistaken file meets the same limits everywhere:

- only a regular file is opened (a FIFO, /dev/zero or a folder is refused before anything is read;
  the open itself does not block), and at most `max_bytes` of it are read; `open_regular_file` is that
  open-and-check alone, for readers of other files (a data shard streamed into numpy), and
  `follow_symlinks=False` refuses a symbolic link too (the report's run files);
- the text must be UTF-8 JSON without NaN or Infinity, and every float finite (1e999 is refused);
  in a file of up to SCAN_BYTES (every kind but a paper-scale rules file), every integer must also lie
  within 64 bits and nothing be nested deeper than `max_depth`. A larger file is parsed with the same
  float checks and Python's own nesting guard, and its kind's parser checks each field it uses
  (rules_io: code lengths, counts, ranges): walking millions of rules again costs ~3x the parse
  (bench/json_reader.py);
- the value must fit the file kind's schema (fields, types, ranges, list lengths, string lengths).

A refusal is a `JsonFileError` (a ValueError, which the command line prints on one line with exit
code 2) naming the file and, for a schema refusal, the field: `RUN/eval.json: field effect_mae_mm.x:
expected a finite number, got 'abc'`. It lives in the lowest package of the data flow, so `search`,
`pddl_export` and `symlearn` share it.

    >>> schema = Obj({"bits": Int(1, 62)}, optional={"note": Str(100)})
    >>> check({"bits": 5}, schema, "f.json")
    >>> try:
    ...     check({"bits": True}, schema, "f.json")
    ... except JsonFileError as e:
    ...     print(e)
    f.json: field bits: expected an integer in 1..62, got True
"""
from __future__ import annotations

import errno
import json
import math
import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

MiB = 1 << 20
DEFAULT_MAX_BYTES = 16 * MiB  # a result file, a manifest, a problem: kilobytes in practice
DEFAULT_MAX_DEPTH = 32  # the deepest file the tools write nests 6 levels
SCAN_BYTES = 16 * MiB  # files up to this size get the depth and integer walk too (a 16 MB file: ~1 s)
INT_LIMIT = 1 << 63  # integers must lie in [-2**63, 2**63): what numpy and torch hold
_REPR_CHARS = 60


class JsonFileError(ValueError):
    """A JSON file refused: not a regular file, too large, not JSON, too deep, a non-finite or huge number,
    or a value of the wrong shape; the message is one line naming the file (and the field)."""


def _short(v) -> str:
    """repr(v) cut to a few dozen characters (one line: repr escapes newlines)."""
    r = repr(v)
    return r if len(r) <= _REPR_CHARS else r[:_REPR_CHARS - 3] + "..."


# ---------------------------------------------------------------------------------------- bounded bytes


def open_regular_file(path: str | os.PathLike, max_bytes: int, what: str = "file", *,
                      follow_symlinks: bool = True) -> BinaryIO:
    """An open binary file object of a regular file of at most `max_bytes`; JsonFileError (one line, naming
    the file) otherwise. For readers that stream a large file (a data shard) instead of reading it whole.

    The file is opened non-blocking and checked with fstat on the open descriptor, so a FIFO does not
    hang the open and a device (/dev/zero), folder or socket is refused before a byte is read. With
    follow_symlinks=False the last part of the path must not be a symbolic link (O_NOFOLLOW: refused,
    not followed). The caller closes the file (use it in a `with`); it may still grow past max_bytes
    while open, so a reader that must stay bounded reads at most max_bytes + 1 bytes (read_bounded_bytes).
    """
    path = Path(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow_symlinks:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise JsonFileError(f"{path}: no such {what}") from None
    except OSError as e:
        if e.errno == errno.ELOOP and not follow_symlinks and os.path.islink(path):
            raise JsonFileError(f"{path}: is a symbolic link, not a regular {what}") from None
        raise JsonFileError(f"{path}: cannot be opened ({e.strerror or type(e).__name__})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO" if stat.S_ISFIFO(st.st_mode)
                    else "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "a socket or other")
            raise JsonFileError(f"{path}: is {kind}, not a regular {what}")
        if st.st_size > max_bytes:
            raise JsonFileError(f"{path}: {st.st_size} bytes, more than the {max_bytes} bytes a {what} may have")
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def read_bounded_bytes(path: str | os.PathLike, max_bytes: int, what: str = "file", *,
                       follow_symlinks: bool = True) -> bytes:
    """The bytes of a regular file of at most `max_bytes`; JsonFileError (one line, naming the file) otherwise.

    Opened and checked by open_regular_file (non-blocking open, fstat on the descriptor: a FIFO does not
    hang, a device or folder is refused before a byte is read; follow_symlinks=False refuses a symbolic
    link); at most max_bytes + 1 bytes are ever read, whatever the file claims or grows to.
    """
    path = Path(path)
    chunks, left = [], max_bytes + 1
    with open_regular_file(path, max_bytes, what, follow_symlinks=follow_symlinks) as f:
        try:
            while left > 0:  # in chunks: a read of max_bytes + 1 at once would allocate all of it up front
                chunk = f.read(min(left, 4 * MiB))
                if not chunk:
                    break
                chunks.append(chunk)
                left -= len(chunk)
        except OSError as e:
            raise JsonFileError(f"{path}: cannot be read ({e.strerror or type(e).__name__})") from None
    data = b"".join(chunks)
    if len(data) > max_bytes:
        raise JsonFileError(f"{path}: more than the {max_bytes} bytes a {what} may have")
    return data


# ------------------------------------------------------------------------------------- bounded parsing


def _refuse_constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def _finite_float(s: str) -> float:
    v = float(s)
    if not math.isfinite(v):
        raise ValueError(f"{s[:40]} is not a finite number")
    return v


def loads_bounded(text: str | bytes, where: str, max_depth: int = DEFAULT_MAX_DEPTH, scan: bool = True):
    """The JSON value of `text`, refusing (JsonFileError naming `where`) invalid JSON, NaN and Infinity and
    non-finite floats (1e999); with `scan`, also integers outside 64 bits and nesting deeper than max_depth."""
    try:
        if isinstance(text, bytes):
            text = text.decode("utf-8")
        value = json.loads(text, parse_constant=_refuse_constant, parse_float=_finite_float)
    except UnicodeDecodeError as e:
        raise JsonFileError(f"{where}: not UTF-8 text (byte {e.start})") from None
    except json.JSONDecodeError as e:
        raise JsonFileError(f"{where}: not valid JSON (line {e.lineno}, column {e.colno}: {e.msg})") from None
    except RecursionError:
        raise JsonFileError(f"{where}: nested deeper than {max_depth} levels") from None
    except ValueError as e:  # NaN / Infinity / 1e999, or an integer of more digits than Python converts
        raise JsonFileError(f"{where}: not valid JSON ({str(e).splitlines()[0][:100]})") from None
    if scan:
        _check_values(value, where, max_depth)
    return value


def _field_name(chain) -> str:
    """'a.b[2].c' from the (parent chain, key) links _check_values keeps (built only for a refusal)."""
    keys = []
    while chain is not None:
        chain, key = chain
        keys.append(key)
    return "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in reversed(keys)).lstrip(".") or "(top)"


def _check_values(value, where: str, max_depth: int) -> None:
    """Walk a parsed value without recursion: nesting depth and 64-bit integers (the first offender named).
    Floats were checked while parsing; the field path is kept as cheap links and spelled out only on refusal."""
    stack = [(value, 0, None)]
    pop, push = stack.pop, stack.append
    while stack:
        v, depth, chain = pop()
        if isinstance(v, dict):
            items = v.items()
        elif isinstance(v, list):
            items = enumerate(v)
        elif isinstance(v, int) and not isinstance(v, bool) and not -INT_LIMIT <= v < INT_LIMIT:
            raise JsonFileError(f"{where}: field {_field_name(chain)}: an integer of {len(str(abs(v)))} digits, "
                                f"outside 64 bits")
        else:
            continue
        if depth >= max_depth:
            raise JsonFileError(f"{where}: nested deeper than {max_depth} levels (at {_field_name(chain)})")
        for k, x in items:
            if isinstance(x, (dict, list)) or (type(x) is int and not -INT_LIMIT <= x < INT_LIMIT):
                push((x, depth + 1, (chain, k)))


def read_json_file(path: str | os.PathLike, schema: "Schema | None" = None, *, what: str = "JSON file",
                   max_bytes: int = DEFAULT_MAX_BYTES, max_depth: int = DEFAULT_MAX_DEPTH,
                   follow_symlinks: bool = True):
    """The JSON value of a regular file, bounded and checked against `schema` (None: any JSON value).

    JsonFileError (one line naming the file, and the field for a schema refusal) for anything else:
    see the module docstring for the limits. follow_symlinks=False refuses a symbolic link (the report's
    run files).
    """
    path = Path(path)
    data = read_bounded_bytes(path, max_bytes, what, follow_symlinks=follow_symlinks)
    value = loads_bounded(data, str(path), max_depth, scan=len(data) <= SCAN_BYTES)
    if schema is not None:
        check(value, schema, str(path))
    return value


# ---------------------------------------------------------------------------------------------- schemas


class Schema:
    """What a JSON value must be; `check` raises JsonFileError naming the field, `describe` says what is expected."""

    def check(self, v, at: str, where: str) -> None:  # pragma: no cover - every schema overrides it
        raise NotImplementedError

    def describe(self) -> str:  # pragma: no cover
        raise NotImplementedError

    def refuse(self, v, at: str, where: str, why: str | None = None):
        """Raise the one-line refusal: file, field, what was expected and what was found."""
        raise JsonFileError(f"{where}: field {at or '(top)'}: {why or f'expected {self.describe()}, got {_short(v)}'}")


def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


@dataclass(frozen=True)
class Int(Schema):
    """An integer (not a boolean) in lo..hi."""

    lo: int = -INT_LIMIT
    hi: int = INT_LIMIT - 1

    def describe(self) -> str:
        if self.lo == -INT_LIMIT and self.hi == INT_LIMIT - 1:
            return "an integer"
        if self.hi == INT_LIMIT - 1:
            return f"an integer >= {self.lo}"
        return f"an integer in {self.lo}..{self.hi}"

    def check(self, v, at, where):
        if not (_is_int(v) and self.lo <= v <= self.hi):
            self.refuse(v, at, where)


@dataclass(frozen=True)
class Num(Schema):
    """A finite number (integer or float, not a boolean) in lo..hi."""

    lo: float = -math.inf
    hi: float = math.inf

    def describe(self) -> str:
        if math.isinf(self.lo) and math.isinf(self.hi):
            return "a finite number"
        if math.isinf(self.hi):
            return f"a finite number >= {self.lo:g}"
        return f"a finite number in {self.lo:g}..{self.hi:g}"

    def check(self, v, at, where):
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                and self.lo <= v <= self.hi):
            self.refuse(v, at, where)


@dataclass(frozen=True)
class Str(Schema):
    """A string of at most max_len characters, matching `pattern` (full match) and among `choices` if given."""

    max_len: int = 4096
    pattern: str | None = None
    choices: tuple[str, ...] | None = None

    def describe(self) -> str:
        if self.choices is not None:
            return "one of " + ", ".join(map(repr, self.choices))
        return f"a string of at most {self.max_len} characters" + (f" matching {self.pattern}" if self.pattern else "")

    def check(self, v, at, where):
        if not (isinstance(v, str) and len(v) <= self.max_len
                and (self.pattern is None or re.fullmatch(self.pattern, v))
                and (self.choices is None or v in self.choices)):
            self.refuse(v, at, where)


@dataclass(frozen=True)
class Bool(Schema):
    """true or false."""

    def describe(self) -> str:
        return "true or false"

    def check(self, v, at, where):
        if not isinstance(v, bool):
            self.refuse(v, at, where)


@dataclass(frozen=True)
class Const(Schema):
    """Exactly this value, of this type (a version 1 is not `true`, nor 1.0)."""

    value: object

    def describe(self) -> str:
        return repr(self.value)

    def check(self, v, at, where):
        if type(v) is not type(self.value) or v != self.value:
            self.refuse(v, at, where)


@dataclass(frozen=True)
class AnyJson(Schema):
    """Any JSON value (its depth and numbers are bounded by the reader)."""

    def describe(self) -> str:
        return "any JSON value"

    def check(self, v, at, where):
        return None


@dataclass(frozen=True)
class OneOf(Schema):
    """The first of `options` the value fits (null is `OneOf(Null(), X)`, see `Opt`)."""

    options: tuple[Schema, ...]

    def describe(self) -> str:
        return " or ".join(o.describe() for o in self.options)

    def check(self, v, at, where):
        errors = []
        for o in self.options:
            try:
                o.check(v, at, where)
                return
            except JsonFileError as e:
                errors.append(e)
        others = [o for o in self.options if not isinstance(o, Null)]
        if v is not None and len(others) == 1:  # `X or null` and not null: X's own refusal names the inner field
            raise errors[self.options.index(others[0])]
        self.refuse(v, at, where)


@dataclass(frozen=True)
class Null(Schema):
    """null."""

    def describe(self) -> str:
        return "null"

    def check(self, v, at, where):
        if v is not None:
            self.refuse(v, at, where)


def Opt(schema: Schema) -> Schema:  # noqa: N802 (reads as a type in schemas)
    """`schema` or null."""
    return OneOf((Null(), schema))


@dataclass(frozen=True)
class List(Schema):
    """A list of min_len..max_len items, each fitting `item`."""

    item: Schema
    max_len: int
    min_len: int = 0

    def describe(self) -> str:
        return f"a list of {self.min_len}..{self.max_len} items"

    def check(self, v, at, where):
        if not isinstance(v, list):
            self.refuse(v, at, where)
        if not self.min_len <= len(v) <= self.max_len:
            self.refuse(v, at, where, f"a list of {len(v)} items, expected {self.min_len}..{self.max_len}")
        for i, x in enumerate(v):
            self.item.check(x, f"{at}[{i}]", where)


@dataclass(frozen=True)
class Tuple(Schema):
    """A list of exactly len(items) values, the i-th fitting items[i]."""

    items: tuple[Schema, ...]

    def describe(self) -> str:
        return f"a list of {len(self.items)} items ({', '.join(i.describe() for i in self.items)})"

    def check(self, v, at, where):
        if not isinstance(v, list) or len(v) != len(self.items):
            self.refuse(v, at, where)
        for i, (x, s) in enumerate(zip(v, self.items)):
            s.check(x, f"{at}[{i}]", where)


@dataclass(frozen=True)
class Map(Schema):
    """An object of at most max_len entries with free keys (at most key_len characters), each value fitting `value`."""

    value: Schema
    max_len: int = 10_000
    key_len: int = 256

    def describe(self) -> str:
        return f"an object of at most {self.max_len} entries"

    def check(self, v, at, where):
        if not isinstance(v, dict):
            self.refuse(v, at, where)
        if len(v) > self.max_len:
            self.refuse(v, at, where, f"an object of {len(v)} entries, expected at most {self.max_len}")
        for k, x in v.items():
            if len(k) > self.key_len:
                self.refuse(k, at, where, f"a key of {len(k)} characters, expected at most {self.key_len}")
            self.value.check(x, f"{at}.{k}" if at else k, where)


@dataclass(frozen=True)
class Obj(Schema):
    """An object with the `required` fields, perhaps the `optional` ones, and other keys only if `extra`."""

    required: dict = field(default_factory=dict)
    optional: dict = field(default_factory=dict)
    extra: bool = True

    def describe(self) -> str:
        return "an object" + (f" with {', '.join(self.required)}" if self.required else "")

    def check(self, v, at, where):
        if not isinstance(v, dict):
            self.refuse(v, at, where)
        for k, s in self.required.items():
            sub = f"{at}.{k}" if at else k
            if k not in v:
                raise JsonFileError(f"{where}: field {sub}: missing")
            s.check(v[k], sub, where)
        for k, s in self.optional.items():
            if k in v:
                s.check(v[k], f"{at}.{k}" if at else k, where)
        if not self.extra:
            unknown = sorted(k for k in v if k not in self.required and k not in self.optional)
            if unknown:
                raise JsonFileError(f"{where}: field {at + '.' if at else ''}{_short(unknown[0])[1:-1]}: "
                                    f"unknown (expected only {', '.join([*self.required, *self.optional])})")


def check(value, schema: Schema, where: str) -> None:
    """Refuse `value` (JsonFileError naming `where` and the field) unless it fits `schema`."""
    schema.check(value, "", where)
