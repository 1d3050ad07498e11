"""The restricted expression interpreter of ${...} and $(eval ...): it walks a
Python expression's AST itself. Literals, operators, comparisons,
conditional expressions, comprehensions, lambdas and f-strings are
evaluated; calls only of the functions it is given (whitelist.py) and of
whitelisted methods; no statements, no names starting with '__' nor
attributes starting with '_'; sizes and steps are bounded (bounds.py)."""

import ast
import math

from . import limits, whitelist
from .bounds import _Budget, _check_format_spec, _check_percent_format, _check_string, _weight
from .errors import _EvalError
from .values import _Block, _Helpers, _Namespace


class _Lambda:
    """A lambda of an expression, callable from Python (sorted's key=)."""

    def __init__(self, interpreter, node, env, defaults):
        self._interpreter = interpreter
        self._node = node
        self._env = env
        self._defaults = defaults

    def __call__(self, *args, **kwargs):
        interpreter = self._interpreter
        arguments = self._node.args
        names = [a.arg for a in arguments.posonlyargs + arguments.args]
        bound = {}
        if len(args) > len(names) and arguments.vararg is None:
            raise _EvalError('lambda takes %d arguments, %d given' % (len(names), len(args)))
        for name, value in zip(names, args):
            bound[name] = value
        if arguments.vararg is not None:
            bound[arguments.vararg.arg] = tuple(args[len(names):])
        extra = {}
        for name, value in kwargs.items():
            if name in names:
                bound[name] = value
            elif arguments.kwarg is not None:
                extra[name] = value
            else:
                raise _EvalError("lambda has no parameter '%s'" % name)
        if arguments.kwarg is not None:
            bound[arguments.kwarg.arg] = extra
        first_default = len(names) - len(self._defaults)
        for index, name in enumerate(names):
            if name not in bound:
                if index >= first_default:
                    bound[name] = self._defaults[index - first_default]
                else:
                    raise _EvalError("lambda is missing argument '%s'" % name)
        for argument, default in zip(arguments.kwonlyargs, arguments.kw_defaults):
            if argument.arg not in bound:
                if argument.arg in kwargs:
                    bound[argument.arg] = kwargs[argument.arg]
                elif default is not None:
                    bound[argument.arg] = interpreter.ev(default, self._env)
                else:
                    raise _EvalError("lambda is missing argument '%s'" % argument.arg)
        interpreter.lambda_depth += 1
        try:
            if interpreter.lambda_depth > limits.MAX_LAMBDA_DEPTH:
                raise _EvalError('lambdas call each other more than %d deep'
                                 % limits.MAX_LAMBDA_DEPTH)
            return interpreter.ev(self._node.body, self._env.child(bound))
        finally:
            interpreter.lambda_depth -= 1

    def __repr__(self):
        return '<lambda>'


class _Env:
    __slots__ = ('lookup', 'frames')

    def __init__(self, lookup, frames=()):
        self.lookup = lookup      # name -> (found, value)
        self.frames = frames      # innermost last: dicts of lambda and comprehension names

    def child(self, frame):
        return _Env(self.lookup, self.frames + (frame,))


_COMPARE = {
    ast.Eq: lambda a, b: a == b, ast.NotEq: lambda a, b: a != b,
    ast.Lt: lambda a, b: a < b, ast.LtE: lambda a, b: a <= b,
    ast.Gt: lambda a, b: a > b, ast.GtE: lambda a, b: a >= b,
    ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
    ast.Is: lambda a, b: a is b, ast.IsNot: lambda a, b: a is not b,
}


class _Interpreter:
    """Evaluates a Python expression's AST: literals, operators, comparisons,
    conditional expressions, comprehensions, lambdas, f-strings, calls of the
    functions it is given and of whitelisted methods. No statements, no
    names or attributes that start with '_'; sizes and steps are bounded."""

    def __init__(self, builtins):
        self.builtins = builtins
        self.budget = _Budget()
        self.lambda_depth = 0
        self._parsed = {}
        self._handlers = {
            ast.Expression: lambda node, env: self.ev(node.body, env),
            ast.Constant: lambda node, env: node.value,
            ast.Name: self._name,
            ast.BinOp: self._binop,
            ast.UnaryOp: self._unaryop,
            ast.BoolOp: self._boolop,
            ast.Compare: self._compare,
            ast.IfExp: lambda node, env: (self.ev(node.body, env) if self.ev(node.test, env)
                                          else self.ev(node.orelse, env)),
            ast.Call: self._call,
            ast.Attribute: lambda node, env: self.getattr(self.ev(node.value, env), node.attr),
            ast.Subscript: self._subscript,
            ast.Slice: lambda node, env: slice(
                None if node.lower is None else self.ev(node.lower, env),
                None if node.upper is None else self.ev(node.upper, env),
                None if node.step is None else self.ev(node.step, env)),
            ast.List: lambda node, env: self._bounded(self._sequence(node.elts, env)),
            ast.Tuple: lambda node, env: self._bounded(tuple(self._sequence(node.elts, env))),
            ast.Set: lambda node, env: self._bounded(set(self._sequence(node.elts, env))),
            ast.Dict: self._dict,
            ast.ListComp: lambda node, env: self._comprehension(node, env, list),
            ast.GeneratorExp: lambda node, env: self._comprehension(node, env, list),
            ast.SetComp: lambda node, env: self._comprehension(node, env, set),
            ast.DictComp: lambda node, env: self._comprehension(node, env, dict),
            ast.Lambda: self._lambda,
            ast.JoinedStr: self._joined_str,
            ast.FormattedValue: self._formatted_value,
        }

    def evaluate(self, source, lookup):
        tree = self._parsed.get(source)
        if tree is None:
            if len(source) > 100000:
                raise _EvalError('an expression of more than 100000 characters')
            text = source.strip()
            try:
                tree = ast.parse(text, mode='eval')
            except SyntaxError:
                try:  # an expression broken over lines of an attribute
                    tree = ast.parse(' '.join(text.split('\n')), mode='eval')
                except SyntaxError as error:
                    raise _EvalError('invalid expression: %s' % error.msg) from None
            if len(self._parsed) < 10000:
                self._parsed[source] = tree
        return self.ev(tree, _Env(lookup))

    def ev(self, node, env):
        self.budget.charge()
        handler = self._handlers.get(type(node))
        if handler is None:
            raise _EvalError('%s is not supported in expressions' % type(node).__name__)
        return handler(node, env)

    def _bounded(self, value):
        _weight(value, self.budget)
        return value

    def _name(self, node, env):
        name = node.id
        for frame in reversed(env.frames):
            if name in frame:
                return frame[name]
        if name.startswith('__'):
            raise _EvalError("name '%s' is not allowed (names may not start with '__')" % name)
        found, value = env.lookup(name)
        if found:
            return value
        if name in self.builtins:
            return self.builtins[name]
        raise _EvalError("name '%s' is not defined" % name)

    def _sequence(self, nodes, env):
        values = []
        for item in nodes:
            if isinstance(item, ast.Starred):
                iterable = self.ev(item.value, env)
                self._check_iterable(iterable)
                values.extend(iterable)
            else:
                values.append(self.ev(item, env))
        return values

    def _check_iterable(self, value):
        if isinstance(value, (str, list, tuple, dict, set, frozenset, type({}.keys()),
                              type({}.values()), type({}.items()))):
            if len(value) > limits.MAX_CONTAINER:
                raise _EvalError('more than %d elements: the work is bounded'
                                 % limits.MAX_CONTAINER)
            self.budget.charge(len(value))
            return
        raise _EvalError('%s is not iterable here' % type(value).__name__)

    def _dict(self, node, env):
        result = {}
        for key, value in zip(node.keys, node.values):
            if key is None:
                result.update(self.ev(value, env))
            else:
                result[self.ev(key, env)] = self.ev(value, env)
        return self._bounded(result)

    # operators
    def _binop(self, node, env):
        left = self.ev(node.left, env)
        right = self.ev(node.right, env)
        op = type(node.op)
        if op is ast.Add:
            result = self._add(left, right)
        elif op is ast.Sub:
            result = left - right
        elif op is ast.Mult:
            result = self._mul(left, right)
        elif op is ast.Div:
            result = left / right
        elif op is ast.FloorDiv:
            result = left // right
        elif op is ast.Mod:
            if isinstance(left, str):
                _check_percent_format(left)
                result = _check_string(left % right, self.budget)
            else:
                result = left % right
        elif op is ast.Pow:
            result = self.power(left, right)
        elif op is ast.LShift:
            if isinstance(right, int) and right > limits.MAX_INT_BITS:
                raise _EvalError('a shift of more than %d bits' % limits.MAX_INT_BITS)
            result = left << right
        elif op is ast.RShift:
            result = left >> right
        elif op is ast.BitOr:
            result = left | right
        elif op is ast.BitXor:
            result = left ^ right
        elif op is ast.BitAnd:
            result = left & right
        else:
            raise _EvalError('operator %s is not supported' % op.__name__)
        if isinstance(result, (list, tuple, dict, set, frozenset)):
            self._bounded(result)
        return result

    def _add(self, left, right):
        if isinstance(left, str) and isinstance(right, str):
            if len(left) + len(right) > limits.MAX_OUTPUT_BYTES:
                raise _EvalError('a string longer than %d characters' % limits.MAX_OUTPUT_BYTES)
            self.budget.charge((len(left) + len(right)) // 64)
        return left + right

    def _mul(self, left, right):
        if isinstance(left, int) and isinstance(right, int):
            if abs(left).bit_length() + abs(right).bit_length() > limits.MAX_INT_BITS:
                raise _EvalError('an integer of more than %d bits' % limits.MAX_INT_BITS)
            return left * right
        sequence, count = None, 0
        if isinstance(left, (str, list, tuple)) and isinstance(right, int):
            sequence, count = left, right
        elif isinstance(right, (str, list, tuple)) and isinstance(left, int):
            sequence, count = right, left
        if sequence is not None and count > 0:
            if isinstance(sequence, str):
                if len(sequence) * count > limits.MAX_OUTPUT_BYTES:
                    raise _EvalError('a string longer than %d characters'
                                     % limits.MAX_OUTPUT_BYTES)
                self.budget.charge(len(sequence) * count // 64)
            elif _weight(sequence, self.budget) * count > limits.MAX_CONTAINER:
                raise _EvalError('a container of more than %d elements: the work is bounded'
                                 % limits.MAX_CONTAINER)
        return left * right

    def power(self, base, exponent, modulo=None):
        if modulo is not None:
            return pow(base, exponent, modulo)
        if (isinstance(base, int) and isinstance(exponent, int) and exponent > 0
                and abs(base) > 1 and exponent * math.log2(abs(base)) > limits.MAX_INT_BITS):
            raise _EvalError('an integer of more than %d bits' % limits.MAX_INT_BITS)
        return base ** exponent

    def _unaryop(self, node, env):
        value = self.ev(node.operand, env)
        op = type(node.op)
        if op is ast.Not:
            return not value
        if op is ast.USub:
            return -value
        if op is ast.UAdd:
            return +value
        return ~value

    def _boolop(self, node, env):
        is_and = isinstance(node.op, ast.And)
        value = None
        for operand in node.values:
            value = self.ev(operand, env)
            if bool(value) != is_and:
                return value
        return value

    def _compare(self, node, env):
        left = self.ev(node.left, env)
        for op, comparator in zip(node.ops, node.comparators):
            right = self.ev(comparator, env)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    # calls, attributes, subscripts
    def _call(self, node, env):
        function = self.ev(node.func, env)
        args = self._sequence(node.args, env)
        kwargs = {}
        for keyword_node in node.keywords:
            if keyword_node.arg is None:
                mapping = self.ev(keyword_node.value, env)
                if not isinstance(mapping, dict):
                    raise _EvalError('** needs a dict')
                kwargs.update(mapping)
            else:
                kwargs[keyword_node.arg] = self.ev(keyword_node.value, env)
        if not callable(function) or isinstance(function, (_Block, _Namespace, _Helpers)):
            raise _EvalError("'%s' is not callable" % type(function).__name__)
        result = function(*args, **kwargs)
        if isinstance(result, (list, tuple, dict, set, frozenset)):
            self._bounded(result)
        elif isinstance(result, str):
            _check_string(result, self.budget)
        return result

    def getattr(self, value, name):
        return whitelist.attribute(self, value, name)

    def _subscript(self, node, env):
        value = self.ev(node.value, env)
        index = self.ev(node.slice, env)
        if isinstance(value, _Namespace):
            return value.get(index)
        if isinstance(value, (_Block, _Helpers, _Lambda)) or callable(value):
            raise _EvalError("'%s' is not subscriptable" % type(value).__name__)
        result = value[index]
        if isinstance(index, slice) and isinstance(result, (list, tuple)):
            self._bounded(result)
        return result

    # comprehensions, lambdas, f-strings
    def _bind(self, target, value, frame):
        if isinstance(target, ast.Name):
            if target.id.startswith('__'):
                raise _EvalError("name '%s' is not allowed" % target.id)
            frame[target.id] = value
        elif isinstance(target, (ast.Tuple, ast.List)):
            self._check_iterable(value)
            items = list(value)
            if len(items) != len(target.elts):
                raise _EvalError('cannot unpack %d values into %d names'
                                 % (len(items), len(target.elts)))
            for sub_target, item in zip(target.elts, items):
                self._bind(sub_target, item, frame)
        else:
            raise _EvalError('only names and tuples of names can be assigned')

    def _comprehension(self, node, env, kind):
        results = []

        def generate(index, inner):
            if index == len(node.generators):
                if kind is dict:
                    results.append((self.ev(node.key, inner), self.ev(node.value, inner)))
                else:
                    results.append(self.ev(node.elt, inner))
                if len(results) > limits.MAX_CONTAINER:
                    raise _EvalError('a comprehension of more than %d elements'
                                     % limits.MAX_CONTAINER)
                return
            generator = node.generators[index]
            if generator.is_async:
                raise _EvalError('async comprehensions are not supported')
            iterable = self.ev(generator.iter, inner)
            self._check_iterable(iterable)
            for item in list(iterable):
                frame = {}
                self._bind(generator.target, item, frame)
                scope = inner.child(frame)
                if all(self.ev(condition, scope) for condition in generator.ifs):
                    generate(index + 1, scope)

        generate(0, env)
        return self._bounded(kind(results))

    def _lambda(self, node, env):
        defaults = [self.ev(default, env) for default in node.args.defaults]
        return _Lambda(self, node, env, defaults)

    def _joined_str(self, node, env):
        text = ''.join(str(self.ev(value, env)) for value in node.values)
        return _check_string(text, self.budget)

    def _formatted_value(self, node, env):
        value = self.ev(node.value, env)
        if isinstance(value, (list, tuple, dict, set, frozenset)):
            self._bounded(value)
        if node.conversion == ord('r'):
            value = repr(value)
        elif node.conversion == ord('s'):
            value = str(value)
        elif node.conversion == ord('a'):
            value = ascii(value)
        spec = '' if node.format_spec is None else self.ev(node.format_spec, env)
        _check_format_spec(spec)
        return format(value, spec)
