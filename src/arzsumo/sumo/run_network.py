"""The network a run drives: the shipped one, one built for the run's geometry (its
approach, its downstream edge) or the user's ``[network]``; checked against the run's
settings before SUMO starts."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from arzsumo.sumo.config import SumoConfig
from arzsumo.sumo.network import (
    NetworkSpec,
    approach_edges,
    approach_length_of,
    approach_of,
    build_network,
)
from arzsumo.sumo.paths import NET_FILE, NETS_ENV, SumoError, nets_dir
from arzsumo.units import ms_to_kmh


def network_spec(cfg: SumoConfig) -> NetworkSpec:
    """The network geometry of a run with ``cfg``: the shipped one with the run's
    approach and downstream edge ``down``."""
    return NetworkSpec(approach_length=cfg.approach_length,
                       approach_piece=cfg.approach_piece, down_speed=cfg.down_speed,
                       down_length=cfg.down_length)


def network_file(cfg: SumoConfig, net_dir: Path | None, workdir: Path) -> Path:
    """The network of a run with ``cfg``: an explicit ``net_dir`` (or
    ``$ARZSUMO_SUMO_NETS``) as it is, checked to have the approach of ``cfg`` and the
    shipped ``down``; else the shipped network for the shipped geometry, and any other
    (:func:`network_spec`) built with netconvert into ``workdir`` (about 0.5 s)."""
    if cfg.layout is not None:       # a [network] table: the user's network, checked
        return cfg.layout.net_file
    spec = network_spec(cfg)
    if spec != NetworkSpec() and net_dir is None and not os.environ.get(NETS_ENV):
        return build_network(workdir / "net", spec)
    shipped = NetworkSpec()
    if (spec.down_speed, spec.down_length) != (shipped.down_speed, shipped.down_length):
        raise SumoError(f"down_speed = {ms_to_kmh(cfg.down_speed):g} km/h and down_length = "
                        f"{cfg.down_length:g} m need a network built for them; allowed: no "
                        f"network directory (the run builds it), or the shipped "
                        f"{ms_to_kmh(shipped.down_speed):g} km/h and {shipped.down_length:g} m")
    net = nets_dir(net_dir) / NET_FILE
    have, pieces = approach_length_of(net), approach_of(net)
    wanted = approach_edges(cfg.approach_length, cfg.approach_piece)
    if abs(have - cfg.approach_length) > 1e-6 or len(pieces) != len(wanted):
        raise SumoError(f"approach_length = {cfg.approach_length:g} m ({_edges(wanted)}) "
                        f"does not match the network {str(net)!r}, whose approach is "
                        f"{have:g} m long ({_edges(pieces)}); allowed: the same (`arzsumo "
                        "build-net --approach-length-m LEN --approach-piece-m P --out "
                        "DIR`), or no network directory so that the run builds it")
    return net


def _edges(ids: Sequence[str]) -> str:
    return f"{len(ids)} edge" + ("" if len(ids) == 1 else "s")
