"""Atomic file and directory writes (results appear complete or not at all), TOML in and out,
JSON-ready values. A leaf utility: imports nothing of arzsumo."""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import tempfile
import tomllib
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


#: permissions of what we write: as ``open`` would create them (temporary files are 0600)
FILE_MODE = 0o666 & ~_umask()
DIR_MODE = 0o777 & ~_umask()


@contextlib.contextmanager
def atomic_file(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; move it into place only on success."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=target.suffix,
                               dir=target.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, FILE_MODE)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def read_toml(path: str | os.PathLike[str], field: str,
              error: type[Exception]) -> tuple[str, dict[str, Any]]:
    """Text and parsed mapping of the TOML file ``path``; a missing, unreadable or invalid
    file raises ``error`` with one line naming ``field`` and the path."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise error(f"{field} = {str(path)!r} does not exist") from None
    except OSError as exc:
        raise error(f"{field} = {str(path)!r} cannot be read: {exc.strerror}") from None
    try:
        return text, tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{path}: not valid TOML: {exc}") from None


_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key)


def toml_value(value: Any) -> str:
    """One TOML value (scalar, array or inline table)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):   # Python spells nan, inf and -inf as TOML does
        return repr(value) if math.isfinite(value) else repr(float(value))
    if isinstance(value, str):
        return json.dumps(value)  # JSON string escapes are valid TOML basic-string escapes
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{_toml_key(k)} = {toml_value(v)}"
                               for k, v in value.items()) + "}"
    raise TypeError(f"cannot write {type(value).__name__} {value!r} as TOML")


def dump_toml(data: Mapping[str, Any]) -> str:
    """TOML text of ``data`` (scalars, lists and nested tables), read back by ``tomllib``
    to the same mapping; used for the resolved scenario of every result."""
    def table(prefix: str, body: Mapping[str, Any]) -> list[str]:
        lines = [f"{_toml_key(k)} = {toml_value(v)}" for k, v in body.items()
                 if not isinstance(v, Mapping)]
        for k, v in body.items():
            if isinstance(v, Mapping):
                name = f"{prefix}.{_toml_key(k)}" if prefix else _toml_key(k)
                lines += ["", f"[{name}]", *table(name, v)]
        return lines

    return "\n".join(table("", data)).lstrip("\n") + "\n"


def json_safe(obj: Any) -> Any:
    """``obj`` with numpy scalars as Python numbers and non-finite floats as None."""
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [json_safe(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, np.generic):
        return json_safe(obj.item())
    return obj
