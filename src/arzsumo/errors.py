"""Exceptions for user mistakes.

Every error a user can cause by a bad argument, preset or scenario value derives from
:class:`ArzsumoError`. The CLI prints such an error as one line and exits with code 2;
anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

#: exit codes of the CLI and the studies (``arzsumo --help`` lists them)
EXIT_USAGE = 2            # a user error: one line on stderr
EXIT_INCOMPLETE = 3       # the PDE twin left the physical domain (partial results written)
EXIT_SOME_FAILED = 4      # some runs were invalid, failed or crashed (the others completed)
EXIT_PREMISE_FAILS = 5    # the scenario's premise does not hold (its report written)


class ArzsumoError(Exception):
    """A user-facing error: the message names the field, the value and what is allowed.

    Raised by :func:`require`, it also carries ``field``, ``value`` and ``allowed``, so a
    caller that knows where the value came from (a scenario key, a CLI option) can restate
    it in the user's terms (:func:`arzsumo.tables.in_user_terms`).
    """

    field: str | None = None
    value: object = None
    allowed: str | None = None
    #: where a scenario key's refusal was raised (``x.toml: [sumo]``) and the key
    at: str | None = None
    key: str | None = None
    #: what follows ``field = `` in the message, for a caller that names the field its way
    reason: str | None = None


class ModelError(ArzsumoError, ValueError):
    """Invalid model parameters or states (e.g. negative density, AO at or above its maximum)."""


class ScenarioError(ArzsumoError, ValueError):
    """An invalid scenario file, key or value."""


class EnvError(ArzsumoError, ValueError):
    """A bad keyword argument or action of a Gymnasium environment (:mod:`arzsumo.gym`)."""


class DemandError(ModelError):
    """A traffic demand the fundamental diagram cannot carry."""


def require(condition: bool, field: str, value: object, allowed: str,
            error: type[ArzsumoError] = ModelError) -> None:
    """Raise ``error`` with a message naming ``field``, ``value`` and what is ``allowed``."""
    if not condition:
        exc = error(f"{field} = {value!r} is not allowed: {allowed}")
        exc.field, exc.value, exc.allowed = field, value, allowed
        raise exc
