"""SymPy expressions written in the language of model files (docs/model-files.md, "Expressions").

A model written in Python reaches the library as model text: every expression is printed here, with every
operation parenthesized, and parsed by the library into the same expression trees a model file gives, which
it differentiates exactly and compiles. No string of the user's is evaluated: only SymPy objects are printed,
and what the language lacks is refused with a ValueError naming it.

Names: a Symbol prints as its name; a dynamic symbol q(t) (``sympy.physics.mechanics.dynamicsymbols``) as
``q`` and its time derivative as the velocity's name (``dq`` unless a phase names its velocities otherwise).

    >>> import sympy as sp
    >>> x, k = sp.symbols("x k")
    >>> to_text(-k * x**2 / 2 + sp.sin(x))
    '((((-1)/2)*k*(x)^(2)) + sin(x))'
"""
import math
import re

import sympy as sp

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")

# SymPy's functions and the language's names for them (arguments in order).
_FUNCTIONS = {
    sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.asin: "asin", sp.acos: "acos", sp.atan: "atan",
    sp.sinh: "sinh", sp.cosh: "cosh", sp.tanh: "tanh", sp.exp: "exp", sp.log: "log", sp.Abs: "abs",
    sp.atan2: "atan2",
}
_RELATIONS = {sp.StrictGreaterThan: ">", sp.StrictLessThan: "<", sp.GreaterThan: ">=", sp.LessThan: "<=",
              sp.Equality: "==", sp.Unequality: "!="}


def _name(name, what):
    if not _NAME.match(name):
        raise ValueError("%s '%s' is not a name of the model-file language (letters, digits and _, not "
                         "starting with a digit)" % (what, name))
    return name


def _number(value):
    if isinstance(value, bool):
        raise ValueError("a truth value where a number belongs: %r" % value)
    if isinstance(value, int):
        return str(value) if value >= 0 else "(%d)" % value
    f = float(value)
    if not math.isfinite(f):
        raise ValueError("%r is not a finite number (the model-file language has none)" % value)
    text = repr(f)
    return text if f >= 0 else "(%s)" % text


def _dynamic_symbol(e):
    """Whether e is q(t): an undefined function of one symbol (sympy.physics.mechanics' dynamicsymbols)."""
    return isinstance(e, sp.core.function.AppliedUndef) and len(e.args) == 1 and e.args[0].is_Symbol


def to_text(expr, velocities=None):
    """The expression in the model-file language.

    velocities: {coordinate name: velocity name} for the time derivatives of dynamic symbols (default: "d" +
    the coordinate's name)."""
    velocities = velocities or {}
    if isinstance(expr, (int, float)) and not isinstance(expr, bool):
        return _number(expr)
    if isinstance(expr, str):
        raise ValueError("a string where an expression belongs: %r (give SymPy expressions or numbers; a "
                         "model file's text is read with hybridcont.model(text=...))" % expr)
    e = sp.sympify(expr)
    return _print(e, velocities)


def _print(e, vel):
    if e is sp.true or e is sp.false:
        return "1" if e is sp.true else "0"
    if e.is_Integer:
        return _number(int(e))
    if e.is_Rational:
        p, q = int(e.p), int(e.q)
        return "(%d/%d)" % (p, q) if p >= 0 else "((%d)/%d)" % (p, q)
    if e.is_Float:
        return _number(float(e))
    if e is sp.pi:
        return "pi"
    if e is sp.E:
        return "exp(1)"
    if e in (sp.oo, -sp.oo, sp.zoo, sp.nan):
        raise ValueError("%s is not a number of the model-file language" % e)
    if e.is_Symbol:
        return _name(e.name, "symbol")
    if isinstance(e, sp.Derivative):
        if len(e.variables) != 1 or not _dynamic_symbol(e.expr) or e.variables[0] != e.expr.args[0]:
            raise ValueError("only first time derivatives of coordinates q(t) are states: %s" % e)
        name = e.expr.func.__name__
        return _name(vel.get(name, "d" + name), "velocity")
    if isinstance(e, sp.core.function.AppliedUndef):
        if not _dynamic_symbol(e):
            raise ValueError("%s: an undefined function of anything but time is no name of the model-file language "
                             "(give coordinates as symbols or dynamic symbols q(t))" % e)
        return _name(e.func.__name__, "coordinate")
    if e.is_Add:
        return "(" + " + ".join(_print(a, vel) for a in e.args) + ")"
    if e.is_Mul:
        return "(" + "*".join(_print(a, vel) for a in e.args) + ")"
    if e.is_Pow:
        base, exponent = e.args
        if exponent == sp.Rational(1, 2):
            return "sqrt(%s)" % _print(base, vel)
        if exponent == -sp.Rational(1, 2):
            return "(1/sqrt(%s))" % _print(base, vel)
        return "(%s)^(%s)" % (_print(base, vel), _print(exponent, vel))
    if type(e) in _RELATIONS:
        return "(%s %s %s)" % (_print(e.args[0], vel), _RELATIONS[type(e)], _print(e.args[1], vel))
    if isinstance(e, sp.And):
        return "(" + " && ".join(_print(a, vel) for a in e.args) + ")"
    if isinstance(e, sp.Or):
        return "(" + " || ".join(_print(a, vel) for a in e.args) + ")"
    if isinstance(e, sp.Not):
        return "(!%s)" % _print(e.args[0], vel)
    if isinstance(e, (sp.Min, sp.Max)):
        name = "min" if isinstance(e, sp.Min) else "max"
        text = _print(e.args[0], vel)
        for a in e.args[1:]:
            text = "%s(%s, %s)" % (name, text, _print(a, vel))
        return text
    for function, name in _FUNCTIONS.items():
        if e.func == function:
            return "%s(%s)" % (name, ", ".join(_print(a, vel) for a in e.args))
    raise ValueError("%s: the model-file language has no %s (functions: abs acos asin atan atan2 cos cosh exp "
                     "log max min sin sinh sqrt tan tanh; powers, comparisons, && || !)" % (e, e.func.__name__))
