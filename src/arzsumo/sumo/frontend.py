"""How a SUMO run is driven: libsumo inside this process, or TraCI to a SUMO process.

libsumo and traci share one API (``lib.simulation``, ``lib.vehicle``, ``lib.trafficlight``
...), so everything after :meth:`arzsumo.sumo.simulation.SumoSimulation.start` uses
``sim.lib`` alike whichever drives the run. libsumo is the fast path and has no GUI; to
watch a run, TraCI drives ``sumo-gui`` (``arzsumo run --gui``). One choice, the
frontend's name, sets both the module and the binary:

* ``"libsumo"``: libsumo, the ``sumo`` binary's options (default);
* ``"traci"``: traci to a ``sumo`` process (same numbers as libsumo for the same seed;
  slower: every call is a socket round trip);
* ``"gui"``: traci to ``sumo-gui``, started playing and closed at the end.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import sys
from dataclasses import dataclass
from types import ModuleType

from arzsumo.sumo.paths import SumoError, sumo_binary

log = logging.getLogger(__name__)

#: the frontends by name: (module, binary)
FRONTENDS: dict[str, tuple[str, str]] = {"libsumo": ("libsumo", "sumo"),
                                         "traci": ("traci", "sumo"),
                                         "gui": ("traci", "sumo-gui")}
#: sumo-gui starts the run at once and closes when it ends (TraCI waits on it otherwise)
GUI_ARGS = ("--start", "true", "--quit-on-end", "true")


def libsumo_module() -> ModuleType:
    """Import libsumo, keeping its import-time version chatter off stdout."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        import libsumo
    if buf.getvalue().strip():
        log.debug("libsumo import: %s", buf.getvalue().strip())
    return libsumo


@dataclass(frozen=True)
class Frontend:
    """The module that drives a run and the binary it runs (see the module docstring)."""

    name: str = "libsumo"

    def __post_init__(self) -> None:
        if self.name not in FRONTENDS:
            raise SumoError(f"frontend = {self.name!r} is not allowed: "
                            f"{', '.join(FRONTENDS)}")

    @property
    def module_name(self) -> str:
        return FRONTENDS[self.name][0]

    @property
    def binary_name(self) -> str:
        return FRONTENDS[self.name][1]

    @property
    def gui(self) -> bool:
        return self.binary_name == "sumo-gui"

    def binary(self) -> str:
        """Path of the binary (a one-line SumoError when it is not installed)."""
        return str(sumo_binary(self.binary_name))

    def extra_args(self) -> tuple[str, ...]:
        """Options only this frontend needs."""
        return GUI_ARGS if self.gui else ()

    def check(self) -> None:
        """Refuse, in one line, a frontend that cannot start here (before any work)."""
        self.binary()
        if self.gui and sys.platform.startswith("linux") and not (
                os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
            raise SumoError("--gui needs a display for sumo-gui, and neither DISPLAY nor "
                            "WAYLAND_DISPLAY is set; allowed: --gui in a desktop session "
                            "(or ssh -X), or the run without --gui")

    def load(self) -> ModuleType:
        """The module that drives the run."""
        if self.module_name == "libsumo":
            return libsumo_module()
        import traci

        return traci

    def start(self, lib: ModuleType, cmd: list[str]) -> None:
        """Start SUMO with ``cmd`` through ``lib`` (:meth:`load`).

        TraCI gets a fixed port: without one, traci starts the binary again on a new port
        after every failed start (a minute of retries when sumo-gui cannot open its
        display). Its retry messages go to no one; SUMO's own output is left alone.
        """
        if self.module_name == "libsumo":
            lib.start(cmd)
            return
        from sumolib.miscutils import getFreeSocketPort

        with contextlib.redirect_stdout(io.StringIO()):
            lib.start(cmd, port=getFreeSocketPort())

    def failed_hint(self) -> str:
        """What to try when the binary did not start ("" for plain SUMO)."""
        if not self.gui:
            return ""
        return (f"; allowed: --gui with a display sumo-gui can open (DISPLAY = "
                f"{os.environ.get('DISPLAY', '')!r}), or the run without --gui")
