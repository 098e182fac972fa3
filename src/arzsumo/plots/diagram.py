"""The identified diagram against SUMO's stationary states, per class.

Two rows (flow against density; speed against area occupancy) by two classes. SUMO's
block states are the scatter; each fitted model is a curve along the stream's measured
class mix (rho_a / rho_h at the operating point); the measured wave speed c is a line of
slope c through the operating point in the flow-density panels (with the mix held, a
class's flow and density move together, so the class panel carries the stream's slope).
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from arzsumo.model.fd import area_occupancy, equilibrium_speeds
from arzsumo.model.params import ModelParameters
from arzsumo.units import ms_to_kmh, veh_m_to_veh_km, veh_s_to_veh_h

NAMES = {"h": "HV", "a": "AV"}


def _curve(p: ModelParameters, rho_h: np.ndarray, mix: float) -> tuple[np.ndarray, ...]:
    """AO, speeds (m/s) along rho_a = mix rho_h, up to the model's jam."""
    ao = area_occupancy(p, rho_h, mix * rho_h)
    keep = ao < 0.999 * min(p.ao_max_h, p.ao_max_a)
    v_h, v_a = equilibrium_speeds(p, rho_h[keep], mix * rho_h[keep])
    return ao[keep], rho_h[keep], v_h, v_a


def diagram_figure(blocks: Mapping[str, np.ndarray], models: Mapping[str, ModelParameters],
                   operating_point: tuple[float, float], waves: Mapping[str, float]
                   ) -> Figure:
    """The figure (module docstring) of SUMO's block states ``blocks`` (``rho_h``, ``rho_a``
    veh/m, ``v_h``, ``v_a`` m/s), the fitted ``models`` by label, the measured mean
    densities ``operating_point`` (veh/m) and upstream wave speed per class (m/s)."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), layout="constrained")
    rho_op = np.array(operating_point)
    mix = rho_op[1] / rho_op[0]
    for col, cls in enumerate(("h", "a")):
        rho, v = blocks[f"rho_{cls}"], blocks[f"v_{cls}"]
        p_any = next(iter(models.values()))
        ao = area_occupancy(p_any, blocks["rho_h"], blocks["rho_a"])
        top, bottom = axes[0, col], axes[1, col]
        top.plot(veh_m_to_veh_km(rho), veh_s_to_veh_h(rho * v), ".", ms=3, alpha=0.3,
                 color="0.45", label="SUMO, 100 m x 30 s blocks")
        bottom.plot(ao, ms_to_kmh(v), ".", ms=3, alpha=0.3, color="0.45")
        grid = np.linspace(1e-4, 3.0 * rho_op[0], 400)
        for k, (label, p) in enumerate(models.items()):
            c_ao, c_rho_h, v_h, v_a = _curve(p, grid, mix)
            v_c = v_h if cls == "h" else v_a
            c_rho = c_rho_h if cls == "h" else mix * c_rho_h
            top.plot(veh_m_to_veh_km(c_rho), veh_s_to_veh_h(c_rho * v_c), f"C{k}", lw=2,
                     label=label)
            bottom.plot(c_ao, ms_to_kmh(v_c), f"C{k}", lw=2, label=label)
        v_op = float(np.mean(v[np.isfinite(v)])) if v.size else np.nan
        r0, q0 = rho_op[col], rho_op[col] * v_op
        dr = np.linspace(-0.5, 0.5, 2) * r0
        top.plot(veh_m_to_veh_km(r0 + dr), veh_s_to_veh_h(q0 + waves[cls] * dr), "k--",
                 lw=1.2, label=f"measured wave {ms_to_kmh(waves[cls]):.1f} km/h")
        top.plot(veh_m_to_veh_km(r0), veh_s_to_veh_h(q0), "k*", ms=11)
        top.set_xlabel(f"{NAMES[cls]} density (veh/km)")
        top.set_ylabel(f"{NAMES[cls]} flow (veh/h)")
        bottom.set_xlabel("area occupancy AO")
        bottom.set_ylabel(f"{NAMES[cls]} speed (km/h)")
        top.set_title(f"{NAMES[cls]}: flow against density (curves at the measured mix)")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
            ax.set_xlim(left=0)
            ax.set_ylim(bottom=0)
        top.legend(fontsize=8, loc="upper right")
    return fig
