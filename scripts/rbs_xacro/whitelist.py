"""What expressions may use besides their own syntax: the builtins and math
functions (bounded where they could run away) and the attributes and
methods of values."""

import math
import re
import string

from . import limits
from .bounds import _check_format_spec, _weight
from .errors import _EvalError
from .values import YamlDict, _Helpers, _Namespace

_STR_METHODS = frozenset([
    'capitalize', 'casefold', 'count', 'endswith', 'find', 'index', 'isalnum', 'isalpha',
    'isascii', 'isdecimal', 'isdigit', 'isidentifier', 'islower', 'isnumeric', 'isspace',
    'istitle', 'isupper', 'lower', 'lstrip', 'partition', 'removeprefix', 'removesuffix',
    'rfind', 'rindex', 'rpartition', 'rstrip', 'startswith', 'strip', 'swapcase', 'title',
    'upper'])
_STR_SPLITS = frozenset(['split', 'rsplit', 'splitlines'])
_STR_PADS = frozenset(['ljust', 'rjust', 'center', 'zfill'])
_LIST_METHODS = frozenset(['count', 'index'])
_DICT_METHODS = frozenset(['get', 'keys', 'values', 'items', 'copy'])
_NUMBER_ATTRIBUTES = frozenset(['real', 'imag', 'conjugate', 'is_integer', 'bit_length',
                                'as_integer_ratio'])


def attribute(interpreter, value, name):
    """The attribute `name` of `value` for an expression: a namespace's member, a
    YAML key, or a whitelisted method or number attribute."""
    if name.startswith('_'):
        raise _EvalError("attribute '%s' is not allowed (names may not start with '_')"
                         % name)
    if isinstance(value, (_Namespace, _Helpers)):
        return value.get(name)
    if isinstance(value, YamlDict):
        if name in value:
            return value[name]
        if name in _DICT_METHODS:
            return getattr(value, name)
        raise _EvalError("no key '%s' in %s" % (name, _short(value)))
    if isinstance(value, str):
        return _string_method(interpreter, value, name)
    if isinstance(value, dict) and name in _DICT_METHODS:
        return getattr(value, name)
    if isinstance(value, (list, tuple)) and name in _LIST_METHODS:
        return getattr(value, name)
    if isinstance(value, (int, float)) and name in _NUMBER_ATTRIBUTES and hasattr(value, name):
        return getattr(value, name)
    raise _EvalError("'%s' has no attribute '%s' that expressions may use"
                     % (type(value).__name__, name))


def _string_method(interpreter, text, name):
    budget = interpreter.budget
    if name in _STR_METHODS:
        return getattr(text, name)
    if name in _STR_SPLITS:
        if len(text) > limits.MAX_CONTAINER:
            raise _EvalError('a string of more than %d characters is not split'
                             % limits.MAX_CONTAINER)
        return getattr(text, name)
    if name in _STR_PADS:
        method = getattr(text, name)

        def pad(width, *rest):
            if isinstance(width, int) and width > limits.MAX_FORMAT_WIDTH:
                raise _EvalError('width %d is above %d' % (width, limits.MAX_FORMAT_WIDTH))
            return method(width, *rest)
        return pad
    if name == 'join':
        def join(iterable):
            interpreter._check_iterable(iterable)
            items = list(iterable)
            size = sum(len(item) for item in items if isinstance(item, str))
            size += len(text) * max(len(items) - 1, 0)
            if size > limits.MAX_OUTPUT_BYTES:
                raise _EvalError('a string longer than %d characters' % limits.MAX_OUTPUT_BYTES)
            budget.charge(size // 64)
            return text.join(items)
        return join
    if name == 'replace':
        def replace(old, new, count=-1):
            if not isinstance(old, str) or not isinstance(new, str):
                raise _EvalError('replace() takes strings')
            occurrences = text.count(old) if old else len(text) + 1
            if count >= 0:
                occurrences = min(occurrences, count)
            if len(text) + occurrences * (len(new) - len(old)) > limits.MAX_OUTPUT_BYTES:
                raise _EvalError('a string longer than %d characters' % limits.MAX_OUTPUT_BYTES)
            return text.replace(old, new, count)
        return replace
    if name == 'format':
        def format_(*args, **kwargs):
            for _, field, spec, _ in string.Formatter().parse(text):
                if field is not None and not re.match(r'^\w*$', field):
                    raise _EvalError("format field '{%s}' may only name or number an "
                                     "argument" % field)
                if spec:
                    _check_format_spec(spec)
            return text.format(*args, **kwargs)
        return format_
    raise _EvalError("'str' has no attribute '%s' that expressions may use" % name)


def _short(value, limit=60):
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + '...'


def _make_builtins(interpreter):
    budget = interpreter.budget

    def sized(value):
        interpreter._check_iterable(value)
        return value

    def safe_range(*args):
        span = range(*args)
        if len(span) > limits.MAX_CONTAINER:
            raise _EvalError('range of more than %d numbers' % limits.MAX_CONTAINER)
        budget.charge(len(span))
        return list(span)

    def safe_sum(iterable, start=0):
        if not isinstance(start, (int, float)):
            raise _EvalError('sum() adds numbers only')
        return sum(sized(iterable), start)

    def safe_str(value=''):
        if isinstance(value, (list, tuple, dict, set, frozenset)):
            _weight(value, budget)
        return str(value)

    def guarded(function):
        def call(iterable=(), *args, **kwargs):
            return function(sized(iterable), *args, **kwargs)
        return call

    names = {
        'abs': abs, 'all': guarded(all), 'any': guarded(any), 'bool': bool, 'chr': chr,
        'dict': lambda *args, **kwargs: dict(*[sized(a) for a in args], **kwargs),
        'divmod': divmod, 'enumerate': lambda iterable, start=0: list(enumerate(sized(iterable),
                                                                              start)),
        'filter': lambda function, iterable: list(filter(function, sized(iterable))),
        'float': float, 'int': int, 'len': len, 'list': guarded(list),
        'map': lambda function, *iterables: list(map(function, *[sized(i) for i in iterables])),
        'max': max, 'min': min, 'ord': ord, 'pow': interpreter.power, 'range': safe_range,
        'repr': repr, 'reversed': lambda iterable: list(reversed(sized(iterable))),
        'round': round, 'set': guarded(set), 'sorted': guarded(sorted), 'str': safe_str,
        'sum': safe_sum, 'tuple': guarded(tuple),
        'zip': lambda *iterables: list(zip(*[sized(i) for i in iterables])),
        'hex': hex, 'oct': oct, 'bin': bin, 'True': True, 'False': False, 'None': None,
    }
    math_members = {}
    for name in dir(math):
        if name.startswith('_') or name in ('factorial', 'comb', 'perm', 'prod', 'lcm'):
            continue
        math_members[name] = getattr(math, name)
    math_members['pow'] = math.pow
    names.update(math_members)
    names['pow'] = interpreter.power
    names['math'] = _Helpers('math', math_members)
    return names
