"""Gate 3, instability: does the open loop keep, or grow, its waves?

The paper's premise (section 5, "Open-loop and closed-loop results") is an open loop
that oscillates and does not converge to its equilibrium, which the controllers then
stabilise. Two measures on open-loop runs:

(a) :func:`amplification_gate`: the oscillation amplitude (each place's temporal sd of
    block-mean speeds, :func:`arzsumo.evaluation.waves.temporal_sd`) against x, and its
    amplification over the section, the mean amplitude at the upstream end (x near 0)
    over that at the downstream end (x near L, the meter). Waves born at the merge that
    grow as they travel upstream give > 1.
(b) :func:`pulse_gate`: a paired pulse test. A baseline run and a pulse run on the same
    seed (the meter held red for 20-30 s at t0 in the pulse run); the deviation norm
    D(t) = ||pulse - baseline||, L2 over x, per class and in total. A stable stream
    loses the perturbation within a round trip or two of its characteristics, T = L / v
    + L / |lambda| (:func:`round_trip_time`): the gate *fails* (stable: the premise does
    not hold) when D's excess over a floor falls below ``pulse_decay_fraction`` of its
    peak within ``pulse_round_trips`` T after t0, and passes when it does not (it grows
    or persists).

The floor F is the D that two runs differing only by chance give (e.g. the norm between
the baselines of two seeds): a pulse run whose vehicles draw other random numbers after
the pulse decorrelates from its baseline, so its D never falls to 0 even when the stream
is stable. Independent noise adds to the pulse's deviation in quadrature, so the excess
is sqrt(D^2 - F^2) (0 where D <= F), proportional to the pulse's own deviation. SI units:
s, m, m/s; D in m/s m^(1/2).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from arzsumo.errors import require
from arzsumo.evaluation.waves import growth_upstream, temporal_sd
from arzsumo_studies.gates.gates import GateResult, PremiseError, PremiseThresholds

#: places averaged at each end of the section for the amplification
END_PLACES = 2


def _finite_mean(values: np.ndarray) -> float:
    """Mean of the finite values (NaN when none)."""
    v = values[np.isfinite(values)]
    return float(v.mean()) if v.size else math.nan


def amplification_gate(blocks: np.ndarray, x: np.ndarray, length: float,
                       name: str = "class", thresholds: PremiseThresholds | None = None,
                       end_places: int = END_PLACES) -> GateResult:
    """Gate 3a: the oscillation amplitude against x and its amplification upstream.

    Parameters
    ----------
    blocks : ndarray (T, N)
        Block-mean speeds of the open loop, m/s (NaN where a block is empty).
    x : ndarray (N,)
        Block centres, m from the inlet (increasing).
    length : float
        The section length L (the meter at x = L), m.
    name : str
        The class (or ``"total"``); the gate is named ``amplification[name]``.
    thresholds : PremiseThresholds, optional
        ``min_amplification`` is used.
    end_places : int
        Places averaged at each end.

    Returns
    -------
    GateResult
        ``value``: mean amplitude of the ``end_places`` most upstream places over that of
        the most downstream ones (1; NaN when either is not finite or the downstream one
        is 0); passed when >= ``min_amplification``. ``detail``: ``x_m``,
        ``amplitude_ms`` (per place), ``growth_per_m`` (the log-linear growth upstream,
        :func:`arzsumo.evaluation.waves.growth_upstream`), ``upstream_ms``,
        ``downstream_ms``.
    """
    th = thresholds or PremiseThresholds()
    b, xs = np.asarray(blocks, float), np.asarray(x, float)
    require(b.ndim == 2 and xs.shape == (b.shape[1],) and b.shape[1] >= 2 * end_places,
            "blocks", b.shape, f"a (blocks, places) array with one x per place and at "
            f"least {2 * end_places} places", PremiseError)
    amp = temporal_sd(b)
    up, down = _finite_mean(amp[:end_places]), _finite_mean(amp[-end_places:])
    ratio = up / down if math.isfinite(up) and math.isfinite(down) and down > 0 \
        else math.nan
    detail = {"x_m": xs.tolist(), "amplitude_ms": amp.tolist(), "upstream_ms": up,
              "downstream_ms": down, "growth_per_m": growth_upstream(xs, amp, length)}
    return GateResult(f"amplification[{name}]", ratio, th.min_amplification,
                      bool(ratio >= th.min_amplification), detail)


def round_trip_time(length: float, v_down: float, lambda_up: float) -> float:
    """T = L / v + L / |lambda|: down the section at v, back up at lambda, s.

    Parameters
    ----------
    length : float
        L, m.
    v_down : float
        A free or characteristic downstream speed (> 0), m/s.
    lambda_up : float
        The upstream characteristic speed (lambda_4, != 0; its sign is ignored), m/s.
    """
    require(math.isfinite(length) and length > 0, "length", length, "a length > 0, m",
            PremiseError)
    require(math.isfinite(v_down) and v_down > 0, "v_down", v_down,
            "a downstream speed > 0, m/s", PremiseError)
    require(math.isfinite(lambda_up) and lambda_up != 0, "lambda_up", lambda_up,
            "a non-zero upstream speed, m/s", PremiseError)
    return length / v_down + length / abs(lambda_up)


def deviation_norm(baseline: np.ndarray, pulse: np.ndarray, dx: float) -> np.ndarray:
    """D(t) = sqrt(sum over x of (pulse - baseline)^2 dx): the L2 norm over x per period.

    Parameters
    ----------
    baseline, pulse : ndarray (T, N)
        Speed fields of the two runs on one grid, m/s; NaN where either is unobserved.
    dx : float
        Cell length, m.

    Returns
    -------
    ndarray (T,)
        m/s m^(1/2); cells unobserved in either run count at the mean square of the
        observed ones (NaN when a period has none).
    """
    a, b = np.asarray(baseline, float), np.asarray(pulse, float)
    require(a.ndim == 2 and a.shape == b.shape, "pulse", b.shape,
            f"a (periods, places) field of the baseline's shape {a.shape}", PremiseError)
    sq = (b - a) ** 2
    n = np.isfinite(sq).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_sq = np.where(n > 0, np.nansum(sq, axis=1) / np.maximum(n, 1), np.nan)
    return np.sqrt(mean_sq * a.shape[1] * dx)


def smoothed(t: np.ndarray, values: np.ndarray, span_s: float) -> np.ndarray:
    """Centred moving mean of ``values`` over ``span_s`` seconds (NaN skipped; the samples
    ``t`` uniform, s); ``span_s`` of one sample or less returns the values unchanged."""
    v = np.asarray(values, float)
    dt = float(t[1] - t[0]) if len(t) > 1 else 1.0
    k = round(span_s / dt)
    if k <= 1:
        return v
    ok = np.isfinite(v)
    kernel = np.ones(k)
    total = np.convolve(np.where(ok, v, 0.0), kernel, mode="same")
    count = np.convolve(ok.astype(float), kernel, mode="same")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / count, np.nan)


def pulse_response(t: np.ndarray, norm: np.ndarray, t0: float, window: float,
                   fraction: float, floor: float = 0.0,
                   smooth_s: float = 0.0) -> dict[str, float | bool]:
    """Peak and decay of a deviation norm after a pulse at ``t0``.

    Parameters
    ----------
    t : ndarray (T,)
        Times, s (increasing).
    norm : ndarray (T,)
        D(t), any unit (NaN skipped).
    t0 : float
        Pulse start, s.
    window : float
        The decay must happen by t0 + window, s; the peak is sought in [t0, t0 + window].
    fraction : float
        Decayed when the excess sqrt(D^2 - floor^2) < fraction times its peak value.
    floor : float
        The level D keeps without a pulse's effect (same unit as D).
    smooth_s : float
        D is first averaged over this span (:func:`smoothed`), s; against a floor of
        noisy D, 30 s keeps a dip of the noise from counting as the decay.

    Returns
    -------
    dict
        ``peak`` (D at the peak), ``peak_time_s`` and ``decay_time_s`` (s after t0; the
        first time after the peak, anywhere in the record, that the excess falls below
        the fraction of its peak; NaN if never), ``decayed`` (decay_time_s <= window) and
        ``detectable`` (the peak rises above the floor).
    """
    tt = np.asarray(t, float)
    d = smoothed(tt, norm, smooth_s)
    inside = (tt >= t0) & (tt <= t0 + window) & np.isfinite(d)
    require(bool(inside.any()), "norm", "no finite value", f"values of D(t) between "
            f"t0 = {t0} s and t0 + {window} s", PremiseError)
    k = int(np.flatnonzero(inside)[np.argmax(d[inside])])
    with np.errstate(invalid="ignore"):
        excess = np.sqrt(np.maximum(d * d - floor * floor, 0.0))
    after = np.flatnonzero((np.arange(tt.size) > k) & np.isfinite(d)
                           & (excess < fraction * excess[k]))
    detectable = bool(d[k] > floor)
    decay = float(tt[after[0]] - t0) if after.size and detectable else math.nan
    return {"peak": float(d[k]), "peak_time_s": float(tt[k] - t0), "decay_time_s": decay,
            "decayed": bool(math.isfinite(decay) and decay <= window),
            "detectable": detectable}


def pulse_gate(t: np.ndarray, baseline: Mapping[str, np.ndarray],
               pulse: Mapping[str, np.ndarray], dx: float, t0: float, round_trip: float,
               floor: Mapping[str, float] | None = None,
               thresholds: PremiseThresholds | None = None,
               smooth_s: float = 0.0) -> GateResult:
    """Gate 3b: the paired pulse test, decided on the total deviation norm.

    Parameters
    ----------
    t : ndarray (T,)
        Times of the fields' periods, s.
    baseline, pulse : mapping of str to ndarray (T, N)
        Per class (e.g. ``"hv"``, ``"av"``), the speed fields of the baseline and of the
        pulse run on the same seed, m/s, one grid.
    dx : float
        Cell length, m.
    t0 : float
        Start of the pulse (meter held red), s.
    round_trip : float
        T, s (:func:`round_trip_time`).
    floor : mapping of str to float, optional
        The no-effect level of D per class and under ``"total"`` (m/s m^(1/2)); 0 when
        absent.
    thresholds : PremiseThresholds, optional
        ``pulse_decay_fraction`` and ``pulse_round_trips`` are used.
    smooth_s : float
        Span of the moving mean of D before its peak and decay are read, s.

    Returns
    -------
    GateResult
        Named ``pulse``. ``value``: the total's decay time after t0, s (NaN: no decay);
        threshold: the window ``pulse_round_trips`` T, s; passed when the total's peak
        rises above its floor and the total does not decay within the window.
        ``detail``: ``round_trip_s``, ``window_s`` and, per class and ``"total"``, the
        :func:`pulse_response` entries.
    """
    th = thresholds or PremiseThresholds()
    tt, fl = np.asarray(t, float), dict(floor or {})
    require(set(baseline) == set(pulse) and len(baseline) >= 1, "pulse", sorted(pulse),
            f"the classes of the baseline, {sorted(baseline)}", PremiseError)
    require(math.isfinite(round_trip) and round_trip > 0, "round_trip", round_trip,
            "a round-trip time > 0, s", PremiseError)
    window = th.pulse_round_trips * round_trip
    require(tt.size >= 2 and tt[-1] >= t0 + window, "t", f"ending at {tt[-1]} s",
            f"a record reaching t0 + {th.pulse_round_trips} T = {t0 + window} s",
            PremiseError)
    norms = {c: deviation_norm(baseline[c], pulse[c], dx) for c in baseline}
    norms["total"] = np.sqrt(sum(n ** 2 for n in norms.values()))
    out = {c: pulse_response(tt, n, t0, window, th.pulse_decay_fraction, fl.get(c, 0.0),
                             smooth_s) for c, n in norms.items()}
    total = out["total"]
    return GateResult("pulse", float(total["decay_time_s"]), window,
                      bool(total["detectable"] and not total["decayed"]),
                      {"round_trip_s": round_trip, "window_s": window,
                       "smooth_s": smooth_s, **out})


def mean_response_gate(t: np.ndarray, baselines: Sequence[Mapping[str, np.ndarray]],
                       pulses: Sequence[Mapping[str, np.ndarray]], dx: float, t0: float,
                       round_trip: float, floors: Sequence[Mapping[str, float]],
                       thresholds: PremiseThresholds | None = None,
                       smooth_s: float = 0.0) -> GateResult:
    """Gate 3b pooled over seeds: the pulse's mean response.

    One seed's pulse - baseline is the pulse's response plus the decorrelation of two runs
    whose vehicles drew other random numbers after the pulse; where that decorrelation
    reaches the floor within a round trip (Krauss's noise, or a stop-and-go that loses its
    phase), one seed cannot tell a decay from a dip of the noise. Over N seeds the
    decorrelation averages out (its norm about F / sqrt(N), F the two-seed floor) and the
    response does not. The mean difference field per class is read as :func:`pulse_gate`
    reads one seed, against the floors' mean over the seeds / sqrt(N).

    Parameters
    ----------
    t : ndarray (T,)
        Times of every seed's periods (one grid, the same t0), s.
    baselines, pulses : sequence of mapping of str to ndarray (T, N)
        Per seed, per class, the speed fields of its baseline and its pulse run, m/s.
    floors : sequence of mapping of str to float
        Per seed the floor of one seed's D per class and ``"total"`` (m/s m^(1/2)).
    dx, t0, round_trip, thresholds, smooth_s
        As :func:`pulse_gate`.

    Returns
    -------
    GateResult
        Named ``pulse_mean``; value, threshold and ``passed`` as :func:`pulse_gate` on the
        mean response; ``detail`` adds ``seeds`` and the floors used.
    """
    n = len(baselines)
    require(n >= 2 and len(pulses) == n and len(floors) == n, "seeds", n,
            "two or more seeds, each with a baseline, a pulse and a floor", PremiseError)
    classes = sorted(baselines[0])
    # the mean over every seed (NaN where any seed did not observe the cell: a mean over
    # fewer seeds would carry more than F / sqrt(N) of noise)
    mean = {c: np.mean(np.stack([np.asarray(p[c], float) - np.asarray(b[c], float)
                                 for b, p in zip(baselines, pulses, strict=True)]), axis=0)
            for c in classes}
    floor = {}
    for k in [*classes, "total"]:
        given = [f[k] for f in floors if k in f]
        floor[k] = float(np.mean(given)) / math.sqrt(n) if given else 0.0
    zero = {c: np.zeros_like(m) for c, m in mean.items()}
    one = pulse_gate(t, zero, mean, dx, t0, round_trip, floor, thresholds, smooth_s)
    return GateResult("pulse_mean", one.value, one.threshold, one.passed,
                      {**one.detail, "seeds": n, "floor": floor})
