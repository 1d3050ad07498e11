"""The work bounds of expressions: a step budget, the weight of containers,
the length of strings, the width of format specifications."""

import re

from . import limits
from .errors import _EvalError


class _Budget:
    def __init__(self):
        self.steps = 0

    def charge(self, count=1):
        self.steps += count
        if self.steps > limits.MAX_EVAL_STEPS:
            raise _EvalError('expressions take more than %d steps: the work is bounded'
                             % limits.MAX_EVAL_STEPS)


def _weight(value, budget):
    """A container's elements, nested ones and long strings counted; errors
    past limits.MAX_CONTAINER, so that no str() or comparison of it can run away."""
    total = 0
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            total += 1 + len(item) // 64
        elif isinstance(item, dict):
            total += 1
            stack.extend(item.keys())
            stack.extend(item.values())
        elif isinstance(item, (list, tuple, set, frozenset)):
            total += 1
            stack.extend(item)
        else:
            total += 1
        if total > limits.MAX_CONTAINER:
            raise _EvalError('a container of more than %d elements: the work is bounded'
                             % limits.MAX_CONTAINER)
    budget.charge(total)
    return total


def _check_string(text, budget):
    if len(text) > limits.MAX_OUTPUT_BYTES:
        raise _EvalError('a string longer than %d characters' % limits.MAX_OUTPUT_BYTES)
    budget.charge(len(text) // 64)
    return text


def _check_format_spec(spec):
    if '{' in spec or '*' in spec:
        raise _EvalError('nested or starred format specifications are not supported')
    for digits in re.findall(r'\d+', spec):
        if int(digits) > limits.MAX_FORMAT_WIDTH:
            raise _EvalError('format width %s is above %d' % (digits, limits.MAX_FORMAT_WIDTH))


def _check_percent_format(text):
    for match in re.finditer(r'%(?:\([^)]*\))?[-#0 +]*(\*|\d+)?(?:\.(\*|\d+))?', text):
        for group in match.groups():
            if group == '*':
                raise _EvalError("'*' widths are not supported in % formatting")
            if group and int(group) > limits.MAX_FORMAT_WIDTH:
                raise _EvalError('format width %s is above %d' % (group, limits.MAX_FORMAT_WIDTH))
