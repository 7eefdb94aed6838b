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
        raise MechanismError(f"{where}: cannot parse expression {text!r}") from None
    builder = _Builder(set(parameters), where)
    expr = builder.build(tree.body)
    if not isinstance(expr, sympy.Expr):
        raise MechanismError(f"{where}: {text!r} is a condition, not a number")
    # sympy folds 1/0, log(0), oo - oo into zoo, oo, nan: no float means that
    if any(expr.has(c) for c in (sympy.zoo, sympy.oo, -sympy.oo, sympy.nan)):
        raise MechanismError(f"{where}: {text!r} is not finite (a division by zero or a pole)")
    # sqrt(-1) folds to I: a load is a real number
    if expr.has(sympy.I):
        raise MechanismError(f"{where}: {text!r} is not a real number")
    return expr


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
            raise self.fail(f"{node.value!r} is not a number")
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
