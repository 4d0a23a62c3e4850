"""Arithmetic expressions of a framework file (+ - * / ^, parentheses), parsed without eval."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace

from ...errors import ParameterError

_NUMBER = r"\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?"
_TOKEN = re.compile(rf"\s*(?:({_NUMBER})|([A-Za-z_]\w*)|(.))")


@dataclass(frozen=True)
class Expr:
    """A parsed expression: a number, a parameter name, or an operator on sub-expressions."""

    op: str  # "num", "name", "neg", "+", "-", "*", "/", "^"
    args: tuple = ()
    value: float = 0.0
    name: str = ""
    # The file's text, for messages; not part of equality, hashing or repr (cache keys).
    text: str = field(default="", compare=False, repr=False)

    def names(self) -> set[str]:
        """The parameter names the expression uses."""
        if self.op == "name":
            return {self.name}
        return set().union(*(a.names() for a in self.args)) if self.args else set()

    def source(self) -> str:
        """The expression as the file wrote it (or, once decoded without it, rebuilt)."""
        if self.text:
            return self.text
        if self.op in ("num", "name"):
            return repr(self.value) if self.op == "num" else self.name
        a = [x.source() for x in self.args]
        return f"-({a[0]})" if self.op == "neg" else f"({a[0]} {self.op} {a[1]})"

    def evaluate(self, values: dict[str, float]) -> float:
        """The value with the parameters set to `values`."""
        if self.op == "num":
            return self.value
        if self.op == "name":
            return float(values[self.name])
        a = [x.evaluate(values) for x in self.args]
        if self.op == "neg":
            return -a[0]
        if self.op == "+":
            return a[0] + a[1]
        if self.op == "-":
            return a[0] - a[1]
        if self.op == "*":
            return a[0] * a[1]
        if self.op == "/":
            return a[0] / a[1] if a[1] != 0 else math.nan
        return math.pow(a[0], a[1]) if (a[0] > 0 or float(a[1]).is_integer()) else math.nan


def _tokens(text: str, where: str) -> list[tuple[str, str]]:
    out, pos = [], 0
    text = text.strip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            break
        num, name, sym = m.groups()
        if num is not None:
            out.append(("num", num))
        elif name is not None:
            out.append(("name", name))
        elif sym is not None and sym in "+-*/^()":
            out.append(("sym", sym))
        elif sym is not None and not sym.isspace():
            raise ParameterError(f"{where} = {text!r}: unexpected character {sym!r}")
        pos = m.end()
    return out


class _Parser:
    """Recursive descent: sum := term (('+'|'-') term)*, term := unary (('*'|'/') unary)*,
    unary := '-' unary | power, power := atom ('^' unary)?, atom := number | name | (sum)."""

    def __init__(self, tokens: list[tuple[str, str]], text: str, where: str):
        self.tokens, self.pos, self.text, self.where = tokens, 0, text, where

    def fail(self, what: str) -> ParameterError:
        return ParameterError(f"{self.where} = {self.text!r}: {what}")

    def peek(self) -> tuple[str, str] | None:
        return self.tokens[self.pos] if self.pos < len(self.tokens) else None

    def take(self) -> tuple[str, str]:
        tok = self.peek()
        if tok is None:
            raise self.fail("the expression ends too early")
        self.pos += 1
        return tok

    def sum(self) -> Expr:
        left = self.term()
        while self.peek() in (("sym", "+"), ("sym", "-")):
            op = self.take()[1]
            left = Expr(op, (left, self.term()))
        return left

    def term(self) -> Expr:
        left = self.unary()
        while self.peek() in (("sym", "*"), ("sym", "/")):
            op = self.take()[1]
            left = Expr(op, (left, self.unary()))
        return left

    def unary(self) -> Expr:
        if self.peek() == ("sym", "-"):
            self.take()
            return Expr("neg", (self.unary(),))
        if self.peek() == ("sym", "+"):
            self.take()
            return self.unary()
        return self.power()

    def power(self) -> Expr:
        base = self.atom()
        if self.peek() == ("sym", "^"):
            self.take()
            return Expr("^", (base, self.unary()))
        return base

    def atom(self) -> Expr:
        kind, text = self.take()
        if kind == "num":
            return Expr("num", value=float(text))
        if kind == "name":
            return Expr("name", name=text)
        if text == "(":
            inner = self.sum()
            if self.peek() != ("sym", ")"):
                raise self.fail("a '(' is not closed")
            self.take()
            return inner
        raise self.fail(f"unexpected {text!r}")


def parse(value: object, where: str) -> Expr:
    """A file value (a number, or a string holding an expression) as an Expr; `where` names the
    field in errors."""
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ParameterError(f"{where} = {value!r}: expected a number or an expression")
    if not isinstance(value, str):
        if not math.isfinite(float(value)):
            raise ParameterError(f"{where} = {value!r}: must be finite")
        return Expr("num", value=float(value), text=repr(value))
    tokens = _tokens(value, where)
    if not tokens:
        raise ParameterError(f"{where} = {value!r}: empty expression")
    parser = _Parser(tokens, value, where)
    expr = parser.sum()
    if parser.peek() is not None:
        raise parser.fail(f"unexpected {parser.peek()[1]!r}")
    return replace(expr, text=value)
