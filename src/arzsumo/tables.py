"""Scenario tables read in the user's terms: shape, types, SI conversion, and errors.

Every parser of a scenario table describes its keys with :class:`Key` and reads them with
:func:`read_keys`. The dataclasses behind the tables check their meaning in SI with
internal field names (:func:`arzsumo.errors.require`); :func:`in_user_terms` turns such an
error back into the key and the value as written: ``scenarios/x.toml: [sumo]
demand_h_veh_h = -100 is not allowed: a demand >= 0 veh/h``.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, TypeVar

from arzsumo.errors import ArzsumoError, ScenarioError
from arzsumo.io import toml_value

T = TypeVar("T")

#: what a value of each kind must be (the type part of error messages)
KIND_TEXT = {"number": "a finite number", "integer": "an integer", "string": "a string",
             "bool": "true or false", "numbers": "a list of numbers",
             "strings": "a list of strings"}


@dataclass(frozen=True)
class Key:
    """One key of a scenario table: the SI ``field`` it sets (of the dataclass behind the
    table) and its ``kind``: ``"number"`` (finite int or float), ``"integer"``,
    ``"string"``, ``"bool"``, ``"numbers"`` or ``"strings"`` (non-empty lists, read as
    tuples). ``factor`` is user units per SI unit (3.6 for km/h, 3600 for veh/h, 1000 for
    veh/km); ``allowed`` what is allowed in the key's units, replacing the SI check's text
    where that would mislead; ``choices`` the allowed strings (empty: any). ``unit`` (as
    written in files, "" for none) and ``doc`` (one line) are what docs/scenarios.md states.
    """

    field: str
    kind: str = "number"
    factor: float = 1.0
    allowed: str | None = None
    choices: tuple[str, ...] = ()
    unit: str = ""
    doc: str = ""


def written(value: Any) -> str:
    """``value`` as it is written in a TOML file (``-100``, ``"fast"``, ``[1, 2]``)."""
    try:
        return toml_value(value)
    except TypeError:
        return repr(value)


def where(source: str, table: str) -> str:
    """The prefix of a message about ``[table]`` of ``source``: ``x.toml: [sumo]``."""
    return f"{source}: [{table}]"


def not_allowed(at: str, key: str, value: Any, allowed: str,
                error: type[ArzsumoError] = ScenarioError) -> ArzsumoError:
    """``error``: ``{at} {key} = {value as written} is not allowed: {allowed}``, keeping
    ``at``, ``key`` and ``allowed`` for a caller that names the value its way (:func:`restated`)."""
    exc = error(f"{at} {key} = {written(value)} is not allowed: {allowed}")
    exc.at, exc.key, exc.allowed = at, key, allowed
    return exc


def restated(exc: ArzsumoError, at: str, key: str, name: str, value: Any) -> ArzsumoError:
    """``exc`` about ``{at} {key}`` (from :func:`not_allowed`) said of ``name = value``
    instead (the option the user typed); any other error unchanged."""
    if getattr(exc, "at", None) == at and getattr(exc, "key", None) == key:
        return type(exc)(f"{name} = {value} is not allowed: {exc.allowed}")
    return exc


def check_keys(table: Mapping[str, Any], allowed: set[str] | Mapping[str, Any],
               at: str) -> None:
    """Refuse keys of ``table`` outside ``allowed``, naming all of them."""
    unknown = [k for k in table if k not in allowed]
    if unknown:
        what = "key" if len(unknown) == 1 else "keys"
        named = ", ".join(repr(k) + did_you_mean(k, allowed) for k in unknown)
        raise ScenarioError(f"{at} unknown {what} {named}; "
                            f"allowed: {', '.join(sorted(allowed))}")


def did_you_mean(key: str, allowed: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for the closest allowed name, or "" when none is close."""
    close = difflib.get_close_matches(str(key), [str(a) for a in allowed], n=1, cutoff=0.75)
    return f" (did you mean {close[0]!r}?)" if close else ""


def check_renamed(table: Mapping[str, Any], renamed: Mapping[str, str], at: str) -> None:
    """Refuse a key of ``table`` that was renamed, naming its new name (one line)."""
    for old, new in renamed.items():
        if old in table:
            raise ScenarioError(f"{at} {old} was renamed: write {new} = "
                                f"{written(table[old])} instead")


def sub_table(data: Mapping[str, Any], name: str, allowed: set[str] | Mapping[str, Any],
              source: str, renamed: Mapping[str, str] | None = None) -> dict[str, Any]:
    """The ``[name]`` table of ``data`` (empty if absent), its keys checked (``renamed``:
    old -> new names, refused with a hint)."""
    value = data.get(name, {})
    if not isinstance(value, Mapping):
        raise not_allowed(f"{source}:", name, value, f"a table [{name}]")
    check_renamed(value, renamed or {}, where(source, name))
    check_keys(value, allowed, where(source, name))
    return dict(value)


def checked(value: Any, kind: str, at: str, key: str,
            choices: tuple[str, ...] = ()) -> Any:
    """``value`` if it is of ``kind`` (and among ``choices``); a one-line error otherwise."""
    if kind == "number":
        ok = (isinstance(value, int | float) and not isinstance(value, bool)
              and math.isfinite(value))
    elif kind == "integer":
        ok = isinstance(value, int) and not isinstance(value, bool)
    elif kind == "bool":
        ok = isinstance(value, bool)
    elif kind == "numbers":
        ok = isinstance(value, list) and bool(value) and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in value)
    elif kind == "strings":
        ok = isinstance(value, list) and bool(value) and all(
            isinstance(v, str) and (not choices or v in choices) for v in value)
    else:
        ok = isinstance(value, str) and (not choices or value in choices)
    if not ok:
        text = KIND_TEXT[kind]
        if choices:
            text = (f"a list of {', '.join(choices)}" if kind == "strings"
                    else f"one of {', '.join(choices)}")
        raise not_allowed(at, key, value, text)
    return value


def read_keys(table: Mapping[str, Any], keys: Mapping[str, Key], at: str) -> dict[str, Any]:
    """``{field: SI value}`` of the keys of ``table`` that ``keys`` describes."""
    out: dict[str, Any] = {}
    for key, value in table.items():
        spec = keys.get(key)
        if spec is None:
            continue
        value = checked(value, spec.kind, at, key, spec.choices)
        if spec.kind == "numbers":
            value = tuple(float(v) / spec.factor for v in value)
        elif spec.kind == "strings":
            value = tuple(value)
        elif spec.kind == "number":
            value = value / spec.factor
        out[spec.field] = value
    return out


def _user_names(text: str, keys: Mapping[str, Key]) -> str:
    """``text`` with SI field names of same-unit keys replaced by the keys' names."""
    for key, spec in keys.items():
        if spec.field != key and spec.factor == 1.0:
            text = re.sub(rf"\b{re.escape(spec.field)}\b", key, text)
    return text


def in_user_terms(exc: ArzsumoError, at: str, table: Mapping[str, Any],
                  keys: Mapping[str, Key]) -> ScenarioError:
    """``exc`` (raised in SI with a field name) restated as a :class:`ScenarioError`: a
    field that a key of ``table`` sets is named by that key with the value as written; a
    same-unit field left at its default by its key with the default; anything else keeps
    its message, prefixed by ``at``."""
    field = getattr(exc, "field", None)
    matches = [key for key, spec in keys.items() if field is not None and spec.field == field]
    for key in sorted(matches, key=lambda k: k not in table):     # keys written first
        spec = keys[key]
        allowed = spec.allowed or _user_names(str(exc.allowed), keys)
        if key in table:
            return ScenarioError(f"{at} {key} = {written(table[key])} is not allowed: "
                                 f"{allowed}")
        if spec.factor == 1.0:
            return ScenarioError(f"{at} {key} = {written(exc.value)} (the default) is not "
                                 f"allowed: {allowed}")
    return ScenarioError(f"{at} {_user_names(str(exc), keys)}")


def read_section(make: Callable[..., T], table: Mapping[str, Any], keys: Mapping[str, Key],
                 at: str, **extra: Any) -> T:
    """``make(**SI values of the keys of table, **extra)``: the record of a table whose key
    names are already checked; errors name the key and the value as written."""
    si = read_keys(table, keys, at)       # its own errors name key and value
    try:
        return make(**si, **extra)
    except ArzsumoError as exc:
        raise in_user_terms(exc, at, table, keys) from None
