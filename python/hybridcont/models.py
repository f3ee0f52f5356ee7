"""Models: the built-in ones, model files, model text, and models written in Python with SymPy.

    import hybridcont as hc
    slip = hc.model("slip")                       # a built-in model (hc.builtin_models())
    walker = hc.model("compass-gait")             # a shipped model file by its name
    mine = hc.model("path/to/mine.toml")          # a model file
    same = hc.model(text=open("mine.toml").read())

    b = hc.ModelBuilder("ball", description="a ball bouncing on the ground")
    g = b.parameter("g", 1.0, range="(0, inf)")
    y, dy = sp.symbols("y dy")
    b.phase("flight", states=[y, dy], ode={y: dy, dy: -g}, energy=g*y + dy**2/2, event=y,
            reset={y: y, dy: -dy}, anchor=dy)
    ball = b.build()                              # a Model, compiled like a model file

A Model evaluates the time-based shooting map: r and dr at a point u (``evaluate``), the monodromy and
Floquet multipliers (``floquet``), one period of the orbit as a DataFrame (``orbit``).
"""
import numpy as np
import pandas as pd
import sympy as sp
import tomli_w

from . import _hybridcont as native
from . import _paths
from .expressions import to_text


def builtin_models():
    """The names of the built-in C++ models."""
    return list(native.builtin_model_names())


def shipped_models():
    """The names of the model files shipped with the package (``hc.model(name)`` finds them)."""
    import os
    return sorted(f[:-5] for f in os.listdir(_paths.MODELS) if f.endswith(".toml"))


def model(name=None, text=None, set=None, compile=True):
    """A Model: a built-in model's or a shipped model file's name, a model file's path, or model text.

    set: {parameter: value} set before anything is evaluated. A bad model raises ValueError naming the file,
    line and field."""
    if (name is None) == (text is None):
        raise ValueError("hybridcont.model: give a model's name or path, or text= (one of them)")
    if text is not None:
        m = Model(native.model_from_text(text, "<text>", compile), text=text)
    else:
        m = Model(native.make_model(str(name), [], _paths.MODELS, compile), source=str(name))
    for key, value in (set or {}).items():
        m.set_parameter(key, value)
    return m


class Model:
    """A hybrid model of the library, its parameters and its shooting map."""

    def __init__(self, native_model, source=None, text=None):
        self._native = native_model
        self.source = source      # the name or path it was made from (None: text or Python)
        self.text = text          # its model text, when it was made from text or built in Python

    @property
    def name(self):
        return self._native.name

    @property
    def description(self):
        return self._native.description

    @property
    def conservative(self):
        """Whether the model has a first integral (families in H̄) or not (families in a parameter)."""
        return self._native.num_first_integrals > 0

    @property
    def parameters(self):
        """{name: value} of the model's parameters."""
        return dict(self._native.parameters)

    @property
    def phases(self):
        """[(phase name, [state names])] in the cycle's order."""
        return [(name, list(states)) for name, states in self._native.phases]

    @property
    def families(self):
        """The names the model's family rules give its families ([[families]] of a model file), in order."""
        return list(self._native.family_names)

    def set_parameter(self, name, value):
        """Sets a parameter (ValueError for an unknown name or a value outside its range)."""
        self._native.set_parameter(name, float(value))

    def with_parameters(self, **values):
        """A copy with some parameters set."""
        copy = Model(self._native.clone(), self.source, self.text)
        for key, value in values.items():
            copy.set_parameter(key, value)
        return copy

    def _spec(self, free, fix):
        free = [free] if isinstance(free, str) else list(free or [])
        fix = list(fix.items()) if isinstance(fix, dict) else list(fix or [])
        return native.MapSpec(free, [(str(k), float(v)) for k, v in fix])

    def evaluate(self, u, free=None, fix=None, jacobian=True, rtol=None, atol=None):
        """r(u) and dr(u) of the time-based shooting map (paper eq. r): {"r", "dr", "unknowns", "ok",
        "message"}. u in the map's unknowns ("unknowns"; with free parameters, as a study's points with
        ``free``/``fix``). A failed evaluation (an event not found) is ok False with its message."""
        out = self._native.evaluate(np.asarray(u, dtype=float).tolist(), self._spec(free, fix), jacobian, rtol, atol)
        return dict(out)

    def unknowns(self, free=None, fix=None):
        """The names of u's entries in the map's layout (with free parameters after the orbit's)."""
        return list(self._native.unknowns(self._spec(free, fix)))

    def floquet(self, u, free=None, fix=None, rtol=None, atol=None):
        """The orbit's monodromy matrix Φ_T (at the start of its first phase) and Floquet multipliers:
        {"monodromy", "multipliers", "nontrivial", "stable", "stability", "bp_test", "pd_test", "multiplier_error"
        (the multipliers' estimated error: twice the monodromy's defect on its known eigenvectors), "ok",
        "message"}."""
        out = dict(self._native.floquet(np.asarray(u, dtype=float).tolist(), self._spec(free, fix), rtol, atol))
        out["multipliers"] = np.array(out["multipliers"], dtype=complex)
        out["nontrivial"] = np.array(out["nontrivial"], dtype=complex)
        return out

    def monodromy(self, u, free=None, fix=None):
        """Φ_T, the monodromy matrix of the orbit u (None where it cannot be computed)."""
        return self.floquet(u, free, fix)["monodromy"]

    def orbit(self, u, samples=400, rtol=None, atol=None):
        """One period of the orbit u (the model's own layout, no free parameters) as a DataFrame: t, segment,
        phase and each phase's states as "<phase>.<state>" (empty where another phase runs)."""
        out = self._native.trace(np.asarray(u, dtype=float).tolist(), samples, rtol, atol)
        if not out["ok"]:
            raise RuntimeError("the orbit could not be traced: " + out["message"])
        rows = {"t": out["t"], "segment": [s + 1 for s in out["segment"]], "phase": out["phase"]}
        names = [(p, s) for p, states in self.phases for s in states]
        for p, s in names:
            rows["%s.%s" % (p, s)] = [np.nan] * len(out["t"])
        for k, (phase, x) in enumerate(zip(out["phase"], out["x"])):
            states = dict(self.phases)[phase]
            for s, v in zip(states, x):
                rows["%s.%s" % (phase, s)][k] = v
        return pd.DataFrame(rows)

    def __repr__(self):
        pars = ", ".join("%s=%g" % kv for kv in self.parameters.items())
        return "<hybridcont.Model %s (%s; %s)>" % (self.name, " > ".join(p for p, _ in self.phases), pars)


# ----------------------------------------------------------------------------------------------------------
# models written in Python
# ----------------------------------------------------------------------------------------------------------

def _names(items, what):
    out = []
    for item in items:
        if isinstance(item, str):
            out.append(item)
        elif isinstance(item, sp.Symbol):
            out.append(item.name)
        elif isinstance(item, sp.core.function.AppliedUndef):  # a dynamic symbol q(t)
            out.append(item.func.__name__)
        else:
            raise ValueError("%s: %r is not a name (give strings, SymPy symbols or dynamic symbols)" % (what, item))
    return out


class ModelBuilder:
    """A model written in Python: parameters, phases (vector fields, or mechanics from T and V or M(q)),
    symmetries, starts, run settings, families, quantities, observables, constraints and drawing, each as its
    model-file entry
    (docs/model-files.md), with SymPy expressions where the file has expression strings.

    ``text()`` is the model file this builder writes; ``build()`` the Model the library makes of it (its
    expressions parsed, differentiated exactly and compiled, as a model file's are)."""

    def __init__(self, name, title=None, description=None, conservative=True):
        self._doc = {"hybridcont": 1, "name": name}
        if title:
            self._doc["title"] = title
        if description:
            self._doc["description"] = description
        if not conservative:
            self._doc["conservative"] = False
        self._velocities = {}

    def _t(self, expr):
        return to_text(expr, self._velocities)

    def _table(self, mapping):
        return {_names([k], "name")[0]: self._t(v) for k, v in mapping.items()}

    def parameter(self, name, value, range=None, description=None):
        """Declares a parameter; returns its SymPy symbol."""
        entry = {"value": float(value)}
        if range:
            entry["range"] = range
        if description:
            entry["description"] = description
        self._doc.setdefault("parameters", {})[name] = entry
        return sp.Symbol(name)

    def definition(self, name, expr):
        """A named expression of the parameters (``[definitions]``); returns its symbol."""
        self._doc.setdefault("definitions", {})[name] = self._t(expr)
        return sp.Symbol(name)

    def phase(self, name, states, ode, event, reset, anchor=None, energy=None, integrals=None, typical=None,
              let=None):
        """A phase given by its vector field: ``ode`` {state: rate}, the guard ``event`` (the phase ends where
        it crosses zero downward), ``reset`` {next phase's state: expression of this phase's state},
        ``energy`` (its first integral; none in a non-conservative model), ``anchor`` (the first phase's
        Poincaré section)."""
        entry = {"name": name, "states": _names(states, "states")}
        if typical is not None:
            entry["typical"] = [float(v) for v in typical]
        if let:
            entry["let"] = self._table(let)
        entry["ode"] = self._table(ode)
        if energy is not None:
            entry["energy"] = self._t(energy)
        if integrals is not None:
            entry["integrals"] = [self._t(i) for i in integrals]
        entry["event"] = self._t(event)
        entry["reset"] = self._table(reset)
        if anchor is not None:
            entry["anchor"] = self._t(anchor)
        self._doc.setdefault("phases", []).append(entry)

    def mechanical_phase(self, name, coordinates, kinetic=None, potential=None, mass_matrix=None, forces=None,
                         impact=None, event=None, reset=None, anchor=None, pinned=None, ignorable=None,
                         velocities=None, states=None, ode=None, energy=None, typical=None, let=None):
        """A phase given by its mechanics: generalized coordinates (names, symbols or dynamic symbols q(t)),
        the kinetic energy T(q, q̇) (or the mass matrix M(q), a SymPy Matrix or nested lists) and the potential
        V(q); ``impact`` {"constraint": g(q) or [g1, g2], "restitution": e, "relabel": {q: expression}}.
        The tool derives the equations of motion, the energy and the impact law exactly. The velocities of
        dynamic symbols are named "d" + the coordinate (or ``velocities``)."""
        coords = _names(coordinates, "coordinates")
        vel_names = _names(velocities, "velocities") if velocities else ["d" + c for c in coords]
        for c, v in zip(coords, vel_names):
            self._velocities[c] = v
        for p in _names(pinned or [], "pinned"):
            self._velocities.setdefault(p, "d" + p)
        entry = {"name": name, "coordinates": coords}
        if velocities:
            entry["velocities"] = vel_names
        if pinned:
            entry["pinned"] = _names(pinned, "pinned")
        if ignorable:
            entry["ignorable"] = _names(ignorable, "ignorable")
        if states:
            entry["states"] = _names(states, "states")
        if typical is not None:
            entry["typical"] = [float(v) for v in typical]
        if let:
            entry["let"] = self._table(let)
        if kinetic is not None:
            entry["kinetic"] = self._t(kinetic)
        if mass_matrix is not None:
            rows = mass_matrix.tolist() if hasattr(mass_matrix, "tolist") else mass_matrix
            entry["mass_matrix"] = [[self._t(v) for v in row] for row in rows]
        if potential is not None:
            entry["potential"] = self._t(potential)
        if forces:
            entry["forces"] = self._table(forces)
        if ode:
            entry["ode"] = self._table(ode)
        if energy is not None:
            entry["energy"] = self._t(energy)
        if event is not None:
            entry["event"] = self._t(event)
        if anchor is not None:
            entry["anchor"] = self._t(anchor)
        if impact is not None:
            imp = {}
            constraint = impact["constraint"]
            imp["constraint"] = [self._t(c) for c in constraint] if isinstance(constraint, (list, tuple)) \
                else self._t(constraint)
            if "restitution" in impact:
                r = impact["restitution"]
                imp["restitution"] = float(r) if isinstance(r, (int, float)) else self._t(r)
            if "relabel" in impact:
                imp["relabel"] = self._table(impact["relabel"])
            entry["impact"] = imp
        if reset:
            entry["reset"] = self._table(reset)
        self._doc.setdefault("phases", []).append(entry)

    def symmetry(self, name, flip, reverses_time=False):
        """An involution of the model: the states whose signs it flips, per phase ({phase: [states]})."""
        entry = {"name": name, "flip": {p: _names(s, "flip") for p, s in flip.items()}}
        if reverses_time:
            entry["reverses_time"] = True
        self._doc.setdefault("symmetries", []).append(entry)

    def start(self, kind, values=None, word=None):
        """A start of the exploration: kind "singular", "guess" or "simulation"; values {unknown: value or
        expression of the parameters}."""
        entry = {}
        if word:
            entry["word"] = list(word)
        entry["kind"] = kind
        if values:
            entry["values"] = {k: float(v) if isinstance(v, (int, float)) else self._t(v) for k, v in values.items()}
        if "start" in self._doc:
            starts = self._doc["start"] if isinstance(self._doc["start"], list) else [self._doc["start"]]
            starts.append(entry)
            self._doc["start"] = starts
        else:
            self._doc["start"] = entry

    def run(self, **fields):
        """The model's default run (``[run]``): bounds={name: [lo, hi]}, parameter="p", keyframes={...}, ..."""
        self._doc["run"] = fields

    def family(self, name, when=None):
        """A family rule: the first rule whose condition holds names a physical orbit."""
        entry = {"name": name}
        if when is not None:
            entry["when"] = self._t(when)
        self._doc.setdefault("families", []).append(entry)

    def quantity(self, name, expr, description=None):
        """A per-point quantity of the unknowns (a column of the branch files)."""
        entry = {"expression": self._t(expr)}
        if description:
            entry["description"] = description
        self._doc.setdefault("quantities", {})[name] = entry

    def observable(self, name, description=None, value=None, integral=None, mean=None, minimum=None, maximum=None,
                   final=None):
        """What a study measures of an orbit (``[observables]``): exactly one of ``value`` (an expression of the
        unknowns, ``T`` and the parameters), or ``integral``, ``mean``, ``minimum``, ``maximum`` or ``final``
        ({phase: expression}, the phase's states, parameters and definitions). Usable as the model file's are:
        ``until``, ``fix`` with ``free``, ``monitor``, ``extremum``, ``bound``. Returns its name."""
        kinds = {"value": value, "integral": integral, "mean": mean, "minimum": minimum, "maximum": maximum,
                 "final": final}
        given = [k for k, v in kinds.items() if v is not None]
        if len(given) != 1:
            raise ValueError("observable %r: give exactly one of %s (given: %s)"
                             % (name, ", ".join(kinds), ", ".join(given) or "none"))
        kind = given[0]
        entry = {kind: self._t(value) if kind == "value" else self._table(kinds[kind])}
        if description:
            entry["description"] = description
        self._doc.setdefault("observables", {})[_names([name], "observable")[0]] = entry
        return name

    def constraint(self, name, phases=None, final=None, description=None):
        """Admissibility (``[constraints]``): ``phases`` {phase: expression} that stays >= 0 throughout each named
        phase of a physical orbit, or ``final`` {phase: expression} >= 0 at the end of the one phase it names.
        Orbits that violate it are classified ``constraint-violated``; its boundary is located (``CB``)."""
        if (phases is None) == (final is None):
            raise ValueError("constraint %r: give phases={phase: expression} or final={phase: expression}" % name)
        entry = {"final": self._table(final)} if final is not None else self._table(phases)
        if description:
            entry["description"] = description
        self._doc.setdefault("constraints", {})[_names([name], "constraint")[0]] = entry
        return name

    def drawing(self, phases, mass_radius=None, ground=None):
        """How the mechanism is drawn: {phase: {"points": {name: (x, y)}, "lines": [[...]], "masses": [...]}}."""
        d = {}
        if mass_radius is not None:
            d["mass_radius"] = float(mass_radius)
        if ground is not None:
            d["ground"] = bool(ground)
        for phase, spec in phases.items():
            entry = {}
            if "points" in spec:
                entry["points"] = {n: [self._t(xy[0]), self._t(xy[1])] for n, xy in spec["points"].items()}
            for key in ("lines", "masses"):
                if key in spec:
                    entry[key] = spec[key]
            d[phase] = entry
        self._doc["drawing"] = d

    def text(self):
        """The model file this builder writes (TOML)."""
        return tomli_w.dumps(self._doc)

    def build(self, compile=True):
        """The Model the library makes of text() (ValueError naming the field of a bad entry)."""
        text = self.text()
        return Model(native.model_from_text(text, "<%s>" % self._doc["name"], compile), text=text)
