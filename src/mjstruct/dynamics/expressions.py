"""Load expressions: user text checked against a whitelist, then built as sympy objects.

Owns the safe reading of the ``loads`` values of a mechanism file.  The text is parsed
with :mod:`ast` and every node is checked against a short whitelist (numbers, the
names ``q``, ``qdot``, the parameters, ``pi``, ``E``, arithmetic, comparisons, ``and``
/ ``or`` and calls of known functions); the sympy expression is then built from the
tree node by node, so user text is never evaluated as Python.  Also owns the points
where an expression jumps (the switch points of ``Piecewise``, ``Heaviside``,
``sign``, ``Abs``), which the energy integral uses to integrate piecewise-exactly.

Examples
--------
>>> e = parse_expression("-p*Piecewise((10, q < pi), (1, True))", {"p"}, "loads[0].force[0]")
>>> e
-p*Piecewise((10, q < pi), (1, True))
>>> [str(g) for g in switch_functions(e)]
['q - pi']
>>> parse_expression("__import__('os')", set(), "loads[1].moment")
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: loads[1].moment: '__import__' is not a known function or symbol
"""

from __future__ import annotations

import ast
import cmath
import math
import sys
from collections.abc import Callable, Collection
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    import sympy

#: the coordinate and speed symbols every load may use
VARIABLES = ("q", "qdot")

#: functions a load may call (sympy names)
FUNCTIONS = (
    "Piecewise",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "atan2",
    "sinh",
    "cosh",
    "tanh",
    "exp",
    "log",
    "sqrt",
    "Abs",
    "Min",
    "Max",
    "sign",
    "Heaviside",
)

#: named constants
CONSTANTS = ("pi", "E")

#: longest expression text accepted (a guard against pathological input)
MAX_LENGTH = 2000

#: largest exponent of a number raised to a number (sympy would evaluate it exactly)
MAX_EXPONENT = 64

#: deepest nesting of operators, calls and parentheses in an expression
MAX_DEPTH = 100

#: most decimal digits of an exact number (integer or fraction) an expression may build
MAX_DIGITS = 1000

#: the largest double: every constant of a load must fit in one
DOUBLE_MAX = sys.float_info.max


def reserved_names() -> set[str]:
    """Names a parameter may not take."""
    return set(VARIABLES) | set(FUNCTIONS) | set(CONSTANTS) | {"True", "False"}


def parse_expression(text: Any, parameters: Collection[str], where: str) -> sympy.Expr:
    """A load value (a number or an expression text) as a sympy expression.

    Parameters
    ----------
    text : a number or a string such as ``"-M*sin(q)"``.
    parameters : the parameter names the expression may use.
    where : the field named in error messages (``"loads[2].force[0]"``).

    Raises
    ------
    MechanismError
        not a number or a string, unparsable text, an unknown symbol or function, a
        construct outside the whitelist, or a non-finite constant (``1/0``, ``log(0)``).
    """
    import sympy

    if isinstance(text, bool) or not isinstance(text, (int, float, str)):
        raise MechanismError(f"{where}: must be a number or an expression string")
    if not isinstance(text, str):
        value = float(text)
        if value != value or value in (float("inf"), -float("inf")):
            raise MechanismError(f"{where}: must be finite")
        return sympy.Float(value) if isinstance(text, float) else sympy.Integer(text)
    if len(text) > MAX_LENGTH:
        raise MechanismError(f"{where}: expression longer than {MAX_LENGTH} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError:
        raise MechanismError(f"{where}: cannot parse expression {_shown(text)}") from None
    except (RecursionError, MemoryError):
        raise MechanismError(f"{where}: nested deeper than {MAX_DEPTH} levels") from None
    # bounded before sympy sees it: the nesting, the exact numbers it would build and
    # the value of every constant part (sympy evaluates exact powers and products
    # eagerly, at any size)
    _check_depth(tree.body, where)
    _Bounds(where).check(tree.body)
    builder = _Builder(set(parameters), where)
    expr = builder.build(tree.body)
    if not isinstance(expr, sympy.Expr):
        raise MechanismError(f"{where}: {_shown(text)} is a condition, not a number")
    # sympy folds 1/0, log(0), oo - oo into zoo, oo, nan: no float means that
    if any(expr.has(c) for c in (sympy.zoo, sympy.oo, -sympy.oo, sympy.nan)):
        raise MechanismError(
            f"{where}: {_shown(text)} is not finite (a division by zero or a pole)"
        )
    # sqrt(-1) folds to I: a load is a real number
    if expr.has(sympy.I):
        raise MechanismError(f"{where}: {_shown(text)} is not a real number")
    # numbers sympy folded together (1e300*1e300*q) must still fit in a double
    for number in expr.atoms(sympy.Number):
        if not _fits_double(number):
            raise MechanismError(
                f"{where}: the number {_shown(str(number))} does not fit in a double "
                f"(at most {DOUBLE_MAX:.3g})"
            )
    return expr


def _shown(text: str, width: int = 60) -> str:
    """``text`` quoted, cut to ``width`` characters (messages stay one short line)."""
    return repr(text if len(text) <= width else text[: width - 1] + "…")


def _fits_double(number: Any) -> bool:
    try:
        return math.isfinite(float(number))
    except (OverflowError, ValueError):
        return False


def _check_depth(root: ast.AST, where: str) -> None:
    """Refuse a tree nested deeper than :data:`MAX_DEPTH` (walked without recursion)."""
    stack = [(root, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise MechanismError(f"{where}: nested deeper than {MAX_DEPTH} levels")
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))


def _mul(a: float, b: float) -> float:
    """``a * b`` for non-negative bounds, with 0 × inf = 0 (a zero bound stays zero)."""
    return 0.0 if a == 0.0 or b == 0.0 else a * b


def _pow10(x: float) -> float:
    return math.inf if x > 308 else 10.0**x


#: operator nodes: children of an operation without a value of their own
_OPERATORS = (ast.operator, ast.unaryop, ast.cmpop, ast.boolop, ast.expr_context)

#: constant functions evaluated with complex doubles: the loads' functions that cmath
#: has (the rest are left unevaluated)
_COMPLEX_FUNCTIONS: dict[str, Callable[..., complex]] = {
    name: getattr(cmath, name) for name in FUNCTIONS if hasattr(cmath, name)
}


class _Bounds:
    """Bounds of what an expression builds, found on the syntax tree before sympy runs.

    For every node, ``digits``: an upper bound of log10 of the largest numerator or
    denominator of an exact number sympy may form from it (sums and products add the
    digits, a power multiplies them by the largest exponent); and, for a constant part
    (numbers, ``pi``, ``E``), its value in complex doubles.  A bound above
    :data:`MAX_DIGITS`, or a largest constant part that is not a finite real double, is
    bad input.
    """

    def __init__(self, where: str) -> None:
        self.where = where

    def check(self, node: ast.AST) -> None:
        self.judge(node, self.visit(node)[1])

    def judge(self, node: ast.AST, value: complex | None) -> None:
        """Refuse a largest constant part whose value is not a finite real double."""
        if value is None:
            return
        shown = _shown(ast.unparse(node))
        if not (cmath.isfinite(value) and abs(value) <= DOUBLE_MAX):
            raise MechanismError(
                f"{self.where}: {shown} is not finite as a double (a division by zero, a "
                f"pole, or beyond {DOUBLE_MAX:.3g})"
            )
        if abs(value.imag) > 1e-9 * abs(value):
            raise MechanismError(f"{self.where}: {shown} is not a real number")

    def visit(self, node: ast.AST) -> tuple[float, complex | None]:
        """``(digits, value)`` of a node; value None when it is not a constant number."""
        if isinstance(node, ast.Constant):
            v = node.value
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                return 0.0, None
            if isinstance(v, float):
                return 0.0, complex(v)
            digits = math.log10(abs(v)) if v else 0.0
            try:
                return digits, complex(float(v))
            except OverflowError:
                return digits, complex(math.inf)
        if isinstance(node, ast.Name):
            const = {"pi": math.pi, "E": math.e}.get(node.id)
            return (0.5, complex(const)) if const is not None else (0.0, None)
        children = [c for c in ast.iter_child_nodes(node) if not isinstance(c, _OPERATORS)]
        results = [self.visit(c) for c in children]
        digits, value = self.combine(node, results)
        if value is None:
            for child, (_, v) in zip(children, results, strict=True):
                self.judge(child, v)
        if digits > MAX_DIGITS:
            size = f"{digits:.0f}" if digits < 1e9 else f"{digits:.2g}"
            raise MechanismError(
                f"{self.where}: it builds exact numbers of about {size} digits (at most "
                f"{MAX_DIGITS}); write a number that large or that small as a decimal "
                "(such as 1e30)"
            )
        return digits, value

    def combine(
        self, node: ast.AST, parts: list[tuple[float, complex | None]]
    ) -> tuple[float, complex | None]:
        digits = [d for d, _ in parts]
        values = [v for _, v in parts]
        known = bool(values) and all(v is not None for v in values)
        if isinstance(node, ast.UnaryOp) and len(parts) == 1:
            v = values[0]
            if v is None or isinstance(node.op, ast.Not):
                return digits[0], None
            return digits[0], -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp) and len(parts) == 2:
            (da, a), (db, b) = parts
            if isinstance(node.op, ast.Pow):
                bound = _mul(da, _pow10(db))
            elif isinstance(node.op, (ast.Add, ast.Sub)):
                bound = da + db + math.log10(2)
            else:
                bound = da + db
            return bound, _arithmetic(node.op, a, b) if known else None
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            # the function's own name is a child without digits or value
            args = [
                p
                for c, p in zip(ast.iter_child_nodes(node), parts, strict=True)
                if c is not node.func
            ]
            bound = max((d for d, _ in args), default=0.0)
            vals = [v for _, v in args]
            if not vals or any(v is None for v in vals):
                return bound, None
            return bound, _function(node.func.id, vals)  # type: ignore[arg-type]
        return max(digits, default=0.0), None


def _arithmetic(op: ast.operator, a: complex | None, b: complex | None) -> complex:
    """``a op b`` in complex doubles; an overflow or a division by zero gives NaN."""
    assert a is not None and b is not None
    try:
        if isinstance(op, ast.Add):
            return a + b
        if isinstance(op, ast.Sub):
            return a - b
        if isinstance(op, ast.Mult):
            return a * b
        if isinstance(op, ast.Div):
            return a / b
        if isinstance(op, ast.Pow):
            if a.imag == 0 and b.imag == 0 and (a.real >= 0 or float(b.real).is_integer()):
                return complex(math.pow(a.real, b.real))
            return complex(a**b)
    except (OverflowError, ZeroDivisionError, ValueError):
        return complex(math.nan)
    return complex(math.nan)  # an operator the builder refuses


def _function(name: str, args: list[complex]) -> complex | None:
    """A whitelisted function of constants in complex doubles (None: not evaluated)."""
    try:
        if name in _COMPLEX_FUNCTIONS and len(args) == 1:
            return _COMPLEX_FUNCTIONS[name](args[0])
        if name == "Abs" and len(args) == 1:
            return complex(abs(args[0]))
        if any(v.imag != 0 for v in args):
            return None
        x = [v.real for v in args]
        if name == "atan2" and len(x) == 2:
            return complex(math.atan2(x[0], x[1]))
        if name in ("Min", "Max") and x:
            return complex(min(x) if name == "Min" else max(x))
        if name in ("sign", "Heaviside") and len(x) == 1:
            step = (x[0] > 0) - (x[0] < 0)
            return complex(step if name == "sign" else (step + 1) / 2)
    except (OverflowError, ZeroDivisionError, ValueError):
        return complex(math.nan)
    return None


class _Builder:
    """Turns a checked syntax tree into sympy objects, one node at a time."""

    def __init__(self, parameters: set[str], where: str) -> None:
        import sympy

        self.sp = sympy
        self.where = where
        self.names: dict[str, Any] = {v: sympy.Symbol(v, real=True) for v in VARIABLES}
        self.names.update({p: sympy.Symbol(p, real=True) for p in parameters})
        self.names.update({"pi": sympy.pi, "E": sympy.E})
        self.functions: dict[str, Callable[..., Any]] = {f: getattr(sympy, f) for f in FUNCTIONS}

    def fail(self, what: str) -> MechanismError:
        return MechanismError(f"{self.where}: {what}")

    def build(self, node: ast.AST) -> Any:
        sp = self.sp
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool):
                return sp.true if node.value else sp.false
            if isinstance(node.value, int):
                return sp.Integer(node.value)
            if isinstance(node.value, float):
                return sp.Float(node.value)
            raise self.fail(f"{_shown(repr(node.value))} is not a number")
        if isinstance(node, ast.Name):
            if node.id in self.names:
                return self.names[node.id]
            raise self.fail(f"{node.id!r} is not a known function or symbol")
        if isinstance(node, ast.UnaryOp):
            arg = self.build(node.operand)
            if isinstance(node.op, ast.USub):
                return -arg
            if isinstance(node.op, ast.UAdd):
                return arg
            if isinstance(node.op, ast.Not):
                return sp.Not(arg)
        if isinstance(node, ast.BinOp):
            a, b = self.build(node.left), self.build(node.right)
            if isinstance(node.op, ast.Add):
                return a + b
            if isinstance(node.op, ast.Sub):
                return a - b
            if isinstance(node.op, ast.Mult):
                return a * b
            if isinstance(node.op, ast.Div):
                return a / b
            if isinstance(node.op, ast.Pow):
                if a.is_number and b.is_number and abs(complex(b)) > MAX_EXPONENT:
                    raise self.fail(f"exponent {b} is too large")
                return a**b
            raise self.fail(f"operator {type(node.op).__name__} is not allowed")
        if isinstance(node, ast.BoolOp):
            args = [self.build(v) for v in node.values]
            return sp.And(*args) if isinstance(node.op, ast.And) else sp.Or(*args)
        if isinstance(node, ast.Compare):
            ops = {ast.Lt: sp.Lt, ast.LtE: sp.Le, ast.Gt: sp.Gt, ast.GtE: sp.Ge}
            parts, left = [], self.build(node.left)
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                if type(op) not in ops:
                    raise self.fail(f"comparison {type(op).__name__} is not allowed")
                right = self.build(right_node)
                parts.append(ops[type(op)](left, right))
                left = right
            return parts[0] if len(parts) == 1 else sp.And(*parts)
        if isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in self.functions:
                name = ast.unparse(node.func)
                raise self.fail(f"{name!r} is not a known function or symbol")
            if node.keywords:
                raise self.fail(f"{node.func.id}: keyword arguments are not allowed")
            if node.func.id == "Piecewise":
                pieces = []
                for arg in node.args:
                    if not isinstance(arg, ast.Tuple) or len(arg.elts) != 2:
                        raise self.fail("Piecewise takes (value, condition) pairs")
                    pieces.append((self.build(arg.elts[0]), self.build(arg.elts[1])))
                try:
                    return sp.Piecewise(*pieces)
                except (TypeError, ValueError) as exc:
                    raise self.fail(f"Piecewise: {exc}") from None
            args = [self.build(a) for a in node.args]
            try:
                return self.functions[node.func.id](*args)
            except (TypeError, ValueError) as exc:
                raise self.fail(f"{node.func.id}: {exc}") from None
        raise self.fail(f"{type(node).__name__} is not allowed in a load expression")


def switch_functions(expr: sympy.Expr) -> list[sympy.Expr]:
    """Functions g of ``q`` whose sign changes are the jumps of ``expr`` (g = 0 there).

    The conditions of ``Piecewise`` (``a < b`` gives ``a - b``) and the arguments of
    ``Heaviside``, ``sign`` and ``Abs`` (a kink).  Only those that depend on ``q``
    and on nothing but ``q`` and numbers; others are left to the integrator.
    """
    import sympy

    q = sympy.Symbol("q", real=True)
    out: list[sympy.Expr] = []
    for node in sympy.preorder_traversal(expr):
        if isinstance(node, sympy.Piecewise):
            for _, cond in node.args:
                for rel in cond.atoms(sympy.core.relational.Relational):
                    out.append(rel.lhs - rel.rhs)
        elif isinstance(node, (sympy.Heaviside, sympy.sign, sympy.Abs)):
            out.append(node.args[0])
    keep: list[sympy.Expr] = []
    for g in out:
        if g.free_symbols == {q} and not any(g.equals(k) for k in keep):
            keep.append(g)
    return keep
