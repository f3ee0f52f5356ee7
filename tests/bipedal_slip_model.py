"""The bipedal spring-mass model (models/bipedal-slip.toml) written out for the reference tests: its equations
at (k, beta) in units m = l0 = g = 1, its automaton for automaton_reference.replay, and the symmetric walking
and running orbits as roots of the step map (SciPy's DOP853 and Brent's method), independent of hybridcont.
"""
import math

from scipy.integrate import solve_ivp
from scipy.optimize import brentq

OPT = dict(method="DOP853", rtol=1e-12, atol=1e-12)


class Biped:
    """The model's equations at (k, beta), m = l0 = g = 1, written out here."""

    def __init__(self, k, beta):
        self.k, self.S, self.C = k, math.sin(beta), math.cos(beta)
        k, S, C = self.k, self.S, self.C

        def stance(t, s):
            x, y, dx, dy = s
            f = k * (1 / math.hypot(x, y) - 1)
            return [dx, dy, f * x, f * y - 1]

        def double(t, s):
            x, y, dx, dy, d = s
            f1 = k * (1 / math.hypot(x, y) - 1)
            f2 = k * (1 / math.hypot(x - d, y) - 1)
            return [dx, dy, f1 * x + f2 * (x - d), (f1 + f2) * y - 1, 0.0]

        def flight(t, s):
            return [s[2], 0.0, -1.0]

        self.stance, self.double = stance, double
        self.modes = {
            "stance": (stance, [
                ("touchdown", lambda s: s[1] - C, "double", lambda s: [s[0], s[1], s[2], s[3], s[0] + S]),
                ("liftoff", lambda s: 1 - math.hypot(s[0], s[1]), "flight", lambda s: [s[1], s[2], s[3]]),
            ]),
            "double": (double, [
                ("rear_off", lambda s: 1 - math.hypot(s[0], s[1]), "stance", lambda s: [s[0] - s[4], s[1], s[2], s[3]]),
                ("front_off", lambda s: 1 - math.hypot(s[0] - s[4], s[1]), "stance", lambda s: list(s[:4])),
            ]),
            "flight": (flight, [
                ("landing", lambda s: s[0] - C, "stance", lambda s: [-S, s[0], s[1], s[2]]),
            ]),
        }
        self.anchor = ("anchor", lambda s: -s[0], None, None)

    @staticmethod
    def _event(f):
        f.terminal, f.direction = True, -1
        return f

    def walking_step(self, H, y, dy=0.0):
        """Mid-stance (x = 0, height y, vertical speed dy) at level H to the next mid-stance: the segments of
        one step (stance, double, stance) and the state there; None where it is no walking step."""
        k, S, C = self.k, self.S, self.C
        V = y + 0.5 * k * (y - 1) ** 2
        if V + 0.5 * dy * dy >= H:
            return None
        dx = math.sqrt(2 * (H - V) - dy * dy)
        td = self._event(lambda t, s: s[1] - C)
        lo = self._event(lambda t, s: 1 - math.hypot(s[0], s[1]))
        fo = self._event(lambda t, s: 1 - math.hypot(s[0] - s[4], s[1]))
        mid = self._event(lambda t, s: -s[0])
        a = solve_ivp(self.stance, [0, 20], [0, y, dx, dy], events=[td, lo], **OPT)
        if a.t_events[0].size == 0:
            return None
        s1 = a.y_events[0][0]
        s2 = list(s1) + [s1[0] + S]
        b = solve_ivp(self.double, [0, 20], s2, events=[lo, fo], **OPT)
        if b.t_events[0].size == 0:
            return None
        s3 = b.y_events[0][0]
        s4 = [s3[0] - s3[4], s3[1], s3[2], s3[3]]
        c = solve_ivp(self.stance, [0, 20], s4, events=[mid, td, lo], **OPT)
        if c.t_events[0].size == 0:
            return None
        return dict(x1=[0, y, dx, dy], t1=a.t_events[0][0], x2=s2, t2=b.t_events[0][0], x3=s4,
                    t3=c.t_events[0][0], end=c.y_events[0][0])

    def running_step(self, H, y):
        """Mid-stance at height y and level H to lift-off: half a stance, its end, and the flight time."""
        k = self.k
        V = y + 0.5 * k * (y - 1) ** 2
        if V >= H:
            return None
        dx = math.sqrt(2 * (H - V))
        lo = self._event(lambda t, s: 1 - math.hypot(s[0], s[1]))
        a = solve_ivp(self.stance, [0, 20], [0, y, dx, 0], events=lo, **OPT)
        if a.t_events[0].size == 0:
            return None
        s = a.y_events[0][0]
        return dict(x1=[0, y, dx, 0], t1=a.t_events[0][0], lo=s, angle=math.atan2(s[0], s[1]), flight=2 * s[3])

    def walking_start(self, H, low, high):
        """The symmetric walking orbit at H with mid-stance height in (low, high): the file's start values."""
        y = brentq(lambda y: self.walking_step(H, y)["end"][1] - y, low, high, xtol=1e-14)
        w = self.walking_step(H, y)
        s2, s4 = w["x2"], w["x3"]
        return dict(H=H, t1=w["t1"], x1_x=0, x1_y=y, x1_dx=w["x1"][2], x1_dy=0, t2=w["t2"],
                    x2_x=s2[0], x2_y=s2[1], x2_dx=s2[2], x2_dy=s2[3], x2_d=s2[4], t3=w["t1"] + w["t3"],
                    x3_x=s4[0], x3_y=s4[1], x3_dx=s4[2], x3_dy=s4[3], t4=w["t2"],
                    x4_x=s2[0], x4_y=s2[1], x4_dx=s2[2], x4_dy=s2[3], x4_d=s2[4], t5=w["t3"],
                    x5_x=s4[0], x5_y=s4[1], x5_dx=s4[2], x5_dy=s4[3])

    def running_start(self, H, low, high):
        """The symmetric running orbit at H with mid-stance height in (low, high): lift-off at the angle beta."""
        beta = math.atan2(self.S, self.C)
        y = brentq(lambda y: self.running_step(H, y)["angle"] - beta, low, high, xtol=1e-14)
        r = self.running_step(H, y)
        x, yl, vx, vy = r["lo"]
        return dict(H=H, t1=r["t1"], x1_x=0, x1_y=y, x1_dx=r["x1"][2], x1_dy=0, t2=r["flight"],
                    x2_y=yl, x2_dx=vx, x2_dy=vy, t3=2 * r["t1"], x3_x=-x, x3_y=yl, x3_dx=vx, x3_dy=-vy,
                    t4=r["flight"], x4_y=yl, x4_dx=vx, x4_dy=vy, t5=r["t1"], x5_x=-x, x5_y=yl, x5_dx=vx, x5_dy=-vy)
