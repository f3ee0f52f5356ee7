"""An independent reference for the stability of spring-mass running by the apex return map.

The model is the spring-loaded inverted pendulum (SLIP) of Seyfarth, Geyer, Guenther & Blickhan (2002),
"A movement criterion for running", J. Biomech. 35, 649-655, in dimensionless units: mass m = 1, rest leg
length l0 = 1, gravity g = 1. The parameters are the leg stiffness k, the leg angle beta from the vertical at
touch-down (angle of attack 90 deg - beta) and the system energy E.

* Flight: the point mass is ballistic, x'' = 0, y'' = -g. Touch-down happens when the body height falls to
  l0 cos(beta); the foot is then placed at x + l0 sin(beta), ahead of the body (running in +x).
* Stance: a massless linear spring of rest length l0 joins the fixed foot and the mass. Relative to the foot,
  X'' = k (l0 - l) X / (m l), Y'' = k (l0 - l) Y / (m l) - g with l = sqrt(X^2 + Y^2). Lift-off happens when
  l returns to l0 while the leg extends.
* Apex: the flight state with vertical velocity 0. At a fixed energy E the apex is fixed by its height y
  alone, the forward speed being sqrt(2 (E - g y) / m), so one stride is a one-dimensional map
  y_i -> y_{i+1}, the apex return map. A fixed point y* is periodic running; it is stable when the slope of the
  map there, dy_{i+1}/dy_i, has modulus below 1.

Only flight is solved in closed form; stance is integrated with SciPy's DOP853 (rtol = atol = 1e-12) and
lift-off is located by solve_ivp's event root finding on the dense output. Nothing here comes from the
hybridcont package: it is meant to check it.

Functions: `stride` (one stride with its details), `apex_map`, `fixed_points`, `stable_running`, and
`stability_boundary` (the stiffness where `stable_running` changes, by bisection).
"""
import math
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

M = 1.0   # body mass
L0 = 1.0  # rest leg length
G = 1.0   # gravity

RTOL = 1e-12
ATOL = 1e-12
STANCE_HORIZON = 50.0  # a stance longer than this (in units of sqrt(l0/g)) counts as a failed stride
MAX_STEP = 0.05        # the largest stance step, so that no event is stepped over


def _stance_rhs(k):
    """The stance vector field for the state (X, Y, dX, dY) relative to the foot."""
    def rhs(_t, s):
        X, Y, dX, dY = s
        l = math.hypot(X, Y)
        a = k * (L0 - l) / (M * l)
        return [dX, dY, a * X, a * Y - G]
    return rhs


def _liftoff(_t, s):
    """Zero when the leg is back at its rest length (armed for an extending leg only)."""
    return math.hypot(s[0], s[1]) - L0


_liftoff.terminal = True
_liftoff.direction = 1.0


def _fall(_t, s):
    """Zero when the body reaches the ground (Y = 0)."""
    return s[1]


_fall.terminal = True
_fall.direction = -1.0


def _turn_back(_t, s):
    """Zero when the horizontal velocity falls to 0: the body stops moving forward."""
    return s[2]


_turn_back.terminal = True
_turn_back.direction = -1.0


def stance_energy(s, k):
    """The energy of a stance state (X, Y, dX, dY): kinetic + gravitational + spring."""
    X, Y, dX, dY = s
    l = math.hypot(X, Y)
    return 0.5 * M * (dX * dX + dY * dY) + M * G * Y + 0.5 * k * (L0 - l) ** 2


def stride(y_a, k, beta, E):
    """One stride from an apex at height `y_a` with energy `E`, with its details.

    Returns a dict, always with the key "ok" (bool) and "reason" (None, or why the stride failed). A successful
    stride also holds
      "touchdown": the stance state (X, Y, dX, dY) at touch-down, relative to the foot,
      "liftoff":   the stance state at lift-off,
      "t_flight":  the time from the apex to touch-down, "t_stance": the stance duration,
      "energy_error": the largest |energy - E| at touch-down and lift-off (stance energy with the spring),
      "y_next", "dx_next": the next apex height and forward speed.

    The stride fails when the apex is not below E / g (no forward speed), when the apex is below the touch-down
    height l0 cos(beta) (the leg never touches down), when the body reaches the ground or stops moving forward
    in stance, when it does not lift off within STANCE_HORIZON, or when it leaves the ground without upward
    or forward velocity (no flight phase).
    """
    y_a, k, beta, E = float(y_a), float(k), float(beta), float(E)
    kinetic = E - M * G * y_a
    if not kinetic > 0.0:
        return {"ok": False, "reason": "apex at or above E/g: no forward speed"}
    dx_a = math.sqrt(2.0 * kinetic / M)
    y_td = L0 * math.cos(beta)
    drop = y_a - y_td
    if drop < 0.0:
        return {"ok": False, "reason": "apex below the touch-down height"}
    # Ballistic fall from the apex to the touch-down height.
    t_flight = math.sqrt(2.0 * drop / G)
    dy_td = -G * t_flight
    s_td = [-L0 * math.sin(beta), y_td, dx_a, dy_td]
    sol = solve_ivp(_stance_rhs(k), (0.0, STANCE_HORIZON), s_td, method="DOP853", rtol=RTOL, atol=ATOL,
                    events=(_liftoff, _fall, _turn_back), max_step=MAX_STEP)
    if sol.status != 1:
        return {"ok": False, "reason": "no lift-off within the stance horizon" if sol.status == 0
                else "integration failure: " + sol.message}
    if sol.t_events[1].size:
        return {"ok": False, "reason": "the body reached the ground in stance"}
    if sol.t_events[2].size:
        return {"ok": False, "reason": "the body stopped moving forward in stance"}
    t_stance = float(sol.t_events[0][0])
    s_lo = [float(v) for v in sol.y_events[0][0]]
    X, Y, dX, dY = s_lo
    if not dX > 0.0:
        return {"ok": False, "reason": "no forward velocity at lift-off"}
    if not dY > 0.0:
        return {"ok": False, "reason": "no upward velocity at lift-off: no flight"}
    # Ballistic rise from lift-off to the next apex.
    y_next = Y + dY * dY / (2.0 * G)
    energy_error = max(abs(stance_energy(s_td, k) - E), abs(stance_energy(s_lo, k) - E))
    return {"ok": True, "reason": None, "touchdown": s_td, "liftoff": s_lo, "t_flight": t_flight,
            "t_stance": t_stance, "energy_error": energy_error, "y_next": y_next, "dx_next": dX}


def apex_map(y_a, k, beta, E):
    """The apex return map: the next apex height after one stride from an apex at height `y_a`.

    `k` is the leg stiffness, `beta` the leg angle from the vertical at touch-down (radians), `E` the energy.
    Returns None where the stride fails (see `stride`).
    """
    r = stride(y_a, k, beta, E)
    return r["y_next"] if r["ok"] else None


class FixedPoint(NamedTuple):
    """A fixed point of the apex map: apex height, slope dy_{i+1}/dy_i of the map there, |slope| < 1."""
    y: float
    slope: float
    stable: bool


def apex_domain(beta, E):
    """The open interval of apex heights (l0 cos(beta), E/g) on which the apex map may be defined."""
    return L0 * math.cos(beta), E / (M * G)


def map_slope(y, k, beta, E, h=1e-6):
    """The slope dy_{i+1}/dy_i of the apex map at `y` by a central difference.

    The step is `h`, shortened near the touch-down height l0 cos(beta), where the map has a square-root
    singularity (the touch-down speed grows as sqrt(y - l0 cos(beta))); a one-sided difference is used where
    only one neighbour is defined. Returns None when no difference can be formed.
    """
    lo, _ = apex_domain(beta, E)
    if y - lo > 0.0:
        h = min(h, 0.25 * (y - lo))
    fp, fm = apex_map(y + h, k, beta, E), apex_map(y - h, k, beta, E)
    if fp is not None and fm is not None:
        return (fp - fm) / (2.0 * h)
    f0 = apex_map(y, k, beta, E)
    if f0 is None:
        return None
    if fp is not None:
        return (fp - f0) / h
    if fm is not None:
        return (f0 - fm) / h
    return None


EDGE = 1e-10  # the first and last samples sit this far (relative) inside the apex-height interval


def fixed_points(k, beta, E, n=400, xtol=1e-12, h=1e-6):
    """All fixed points y* = apex_map(y*) found on the apex-height interval (l0 cos(beta), E/g).

    The residual r(y) = y - apex_map(y) is sampled at `n` points spanning the interval (the end points moved
    inside by EDGE, relative); every sign change between neighbouring samples where the map is defined is
    refined by Brent's method to `xtol`. Near a fold two fixed points can lie between two samples: where |r|
    has a local minimum at a sample without a sign change, r is minimised (bounded Brent) between the
    neighbouring samples, and a sign change found there gives both roots. (A fixed point where r only touches
    zero is not found.) Returns a list of FixedPoint(y, slope, stable) in increasing y, the slope by
    `map_slope` with step `h`.
    """
    lo, hi = apex_domain(beta, E)
    if not hi > lo:
        return []
    ys = np.linspace(lo, hi, n)
    ys[0] += EDGE * (hi - lo)
    ys[-1] -= EDGE * (hi - lo)

    def residual(y):
        f = apex_map(y, k, beta, E)
        if f is None:
            raise ValueError("apex map undefined inside a bracket")
        return y - f

    res = []
    for y in ys:
        f = apex_map(y, k, beta, E)
        res.append(None if f is None else y - f)

    def refine(a, b):
        try:
            return [brentq(residual, a, b, xtol=xtol, rtol=4.0 * np.finfo(float).eps)]
        except ValueError:
            return []  # the map is undefined somewhere inside: no continuous sign change to refine

    roots = []
    for i, r in enumerate(res):
        if r is None:
            continue
        if r == 0.0:
            roots.append(float(ys[i]))
            continue
        nxt = res[i + 1] if i + 1 < n else None
        if nxt is not None and nxt != 0.0 and (r > 0.0) != (nxt > 0.0):
            roots += refine(ys[i], ys[i + 1])
        prv = res[i - 1] if i > 0 else None
        if (prv is not None and nxt is not None and prv * r > 0.0 and nxt * r > 0.0
                and abs(r) < abs(prv) and abs(r) <= abs(nxt)):
            # A possible pair of close fixed points: look for a sign change near the minimum of |r|.
            sign = 1.0 if r > 0.0 else -1.0
            try:
                m = minimize_scalar(lambda y: sign * residual(y), bounds=(ys[i - 1], ys[i + 1]),
                                    method="bounded", options={"xatol": xtol})
            except ValueError:
                continue
            if m.fun < 0.0:
                roots += refine(ys[i - 1], m.x) + refine(m.x, ys[i + 1])
    out = []
    for y in sorted(roots):
        if out and abs(y - out[-1].y) < 10.0 * xtol:
            continue
        s = map_slope(y, k, beta, E, h)
        if s is None:
            continue
        out.append(FixedPoint(float(y), float(s), bool(abs(s) < 1.0)))
    return out


def stable_running(k, beta, E, **kw):
    """True if the apex map has a stable fixed point (|slope| < 1), False if it has fixed points but none is
    stable, None if it has no fixed point. Keyword arguments go to `fixed_points`."""
    fps = fixed_points(k, beta, E, **kw)
    if not fps:
        return None
    return any(fp.stable for fp in fps)


def stability_boundary(k_in, k_out, beta, E, ktol=1e-4, **kw):
    """The stiffness between `k_in` (stable running) and `k_out` (no stable running) where stable running ends,
    by bisection on `stable_running(k) is True` to within `ktol`. Returns (k_boundary, state at k_out side),
    the state being what `stable_running` gives just outside (False: only unstable fixed points, None: none)."""
    if stable_running(k_in, beta, E, **kw) is not True:
        raise ValueError("k_in is not in stable running")
    outside = stable_running(k_out, beta, E, **kw)
    if outside is True:
        raise ValueError("k_out is in stable running")
    a, b = float(k_in), float(k_out)
    while abs(b - a) > ktol:
        c = 0.5 * (a + b)
        s = stable_running(c, beta, E, **kw)
        if s is True:
            a = c
        else:
            b, outside = c, s
    return 0.5 * (a + b), outside
