"""Attribute values and text: ${...} expressions and $(...) substitutions
(arg, find, env, optenv, eval, dirname, anon) lexed and evaluated, with the
error placed at the file and line of the construct."""

import os

from . import limits
from .bounds import _weight
from .errors import XacroError, _EvalError


def _match_bracket(text, start, opening, closing, quotes):
    """The index of the bracket closing the one at `start`, or -1."""
    depth = 0
    quote = None
    index = start
    length = len(text)
    while index < length:
        char = text[index]
        if quote:
            if char == '\\':
                index += 1
            elif char == quote:
                quote = None
        elif quotes and char in '\'"':
            quote = char
        elif char == opening:
            depth += 1
        elif char == closing:
            depth -= 1
            if depth == 0:
                return index
        index += 1
    return -1


def _lex(text):
    """[(kind, content, offset)]: 'text', 'expr' (${...}) and 'subst' ($(...))."""
    parts = []
    buffer = []
    index = 0
    length = len(text)
    while index < length:
        dollar = text.find('$', index)
        if dollar < 0:
            buffer.append(text[index:])
            break
        if dollar > index:
            buffer.append(text[index:dollar])
        end = dollar
        while end < length and text[end] == '$':
            end += 1
        if end < length and text[end] in '{(':
            if end - dollar >= 2:   # $${ and $$( are a literal ${ and $(
                buffer.append('$' * (end - dollar - 1) + text[end])
                index = end + 1
                continue
            opening = text[end]
            closing = '}' if opening == '{' else ')'
            quotes = opening == '{' or text.startswith('eval', end + 1)
            close = _match_bracket(text, end, opening, closing, quotes)
            if close < 0:
                raise _LexError("unbalanced '$%s' (no closing '%s')" % (opening, closing),
                                dollar, text[dollar:dollar + 40])
            if buffer:
                parts.append(('text', ''.join(buffer), None))
                buffer = []
            parts.append(('expr' if opening == '{' else 'subst', text[end + 1:close], dollar))
            index = close + 1
        else:
            buffer.append(text[dollar:end])
            index = end
    if buffer:
        parts.append(('text', ''.join(buffer), None))
    return [part for part in parts if part[0] != 'text' or part[1]]


class _LexError(Exception):
    def __init__(self, message, offset, excerpt):
        super().__init__(message)
        self.offset = offset
        self.excerpt = excerpt


def _is_real_file(file):
    return bool(file) and not file.startswith('<')


def _excerpt(text, limit=60):
    text = ' '.join(text.split())
    return text if len(text) <= limit else text[:limit] + '...'


def _line_at(text, offset, line):
    if offset is None or line is None:
        return line
    return line + text.count('\n', 0, offset)


class _Substitutions:
    """The evaluation part of the expander (mixed into _Expander, whose state
    it uses: interpreter, args, arg_defaults, base_dir, location, packages,
    anon, resolve() and _arg())."""

    def value(self, text, scope, file, line):
        """The value of `text`: the typed value of a lone ${...}, else a string."""
        try:
            parts = _lex(text)
        except _LexError as error:
            raise XacroError(str(error), file, _line_at(text, error.offset, line),
                             error.excerpt) from None
        results = []
        for kind, content, offset in parts:
            if kind == 'text':
                results.append(content)
            elif kind == 'expr':
                results.append(self._expression(content, scope, file,
                                                _line_at(text, offset, line)))
            else:
                results.append(self._substitution(content, scope, file,
                                                  _line_at(text, offset, line)))
        if len(results) == 1:
            return results[0]
        pieces = [r if isinstance(r, str) else self._to_str(r) for r in results]
        size = sum(len(piece) for piece in pieces)
        if size > limits.MAX_OUTPUT_BYTES:
            raise XacroError('the value would be longer than %d characters'
                             % limits.MAX_OUTPUT_BYTES, file, line, _excerpt(text))
        try:
            self.interpreter.budget.charge(size // 64)
        except _EvalError as error:
            raise XacroError(str(error), file, line, _excerpt(text)) from None
        return ''.join(pieces)

    def text_value(self, text, scope, file, line):
        value = self.value(text, scope, file, line)
        return value if isinstance(value, str) else self._to_str(value)

    def _to_str(self, value):
        if isinstance(value, (list, tuple, dict, set, frozenset)):
            _weight(value, self.interpreter.budget)
        return str(value)

    def _lookup(self, scope):
        def lookup(name):
            prop = scope.find_prop(name)
            if prop is None:
                return False, None
            return True, self.resolve(name, prop)
        return lookup

    def _expression(self, expression, scope, file, line):
        construct = '${%s}' % expression
        saved = self.location
        self.location = (file, line)
        try:
            source = expression
            if '$(' in source:
                source = self._substitute_all(source, scope, file, line)
            return self.interpreter.evaluate(source, self._lookup(scope))
        except XacroError as error:
            if error.construct != construct or error.line != line:
                error.trace.append('in %s at %s:%s' % (construct, file, line))
            raise
        except _EvalError as error:
            raise XacroError(str(error), file, line, construct) from None
        except RecursionError:
            raise XacroError('nested too deeply', file, line, construct) from None
        except MemoryError:
            raise XacroError('out of memory', file, line, construct) from None
        except Exception as error:  # the expression's own Python error
            raise XacroError('%s: %s' % (type(error).__name__, error), file, line,
                             construct) from None
        finally:
            self.location = saved

    def _substitute_all(self, text, scope, file, line):
        """`text` with its $(...) replaced (inside a ${...})."""
        result = []
        try:
            parts = _lex(text)
        except _LexError as error:
            raise _EvalError(str(error)) from None
        for kind, content, _ in parts:
            if kind == 'text':
                result.append(content)
            elif kind == 'subst':
                result.append(self._substitution(content, scope, file, line))
            else:
                result.append('${%s}' % content)
        return ''.join(result)

    def _substitution(self, body, scope, file, line):
        construct = '$(%s)' % body
        try:
            command, _, rest = body.strip().partition(' ')
            rest = rest.strip()
            if command == 'eval':
                return self._to_str(self._eval_substitution(rest, scope))
            if '$(' in rest:
                rest = self._substitute_all(rest, scope, file, line)
            if command == 'arg':
                return self._arg(rest)
            if command == 'find':
                return self.packages.find(rest)
            if command == 'env':
                if rest not in os.environ:
                    raise _EvalError("environment variable '%s' is not set" % rest)
                return os.environ[rest]
            if command == 'optenv':
                name, _, default = rest.partition(' ')
                return os.environ.get(name, default.strip())
            if command == 'dirname':
                return os.path.dirname(os.path.abspath(file)) if _is_real_file(file) \
                    else self.base_dir
            if command == 'anon':
                if rest not in self.anon:
                    self.anon[rest] = '%s_%d_%d' % (rest, os.getpid(), len(self.anon))
                return self.anon[rest]
            raise _EvalError("unknown substitution '$(%s ...)' (arg, find, env, optenv, eval, "
                             "dirname and anon are known)" % command)
        except XacroError as error:
            error.trace.append('in %s at %s:%s' % (construct, file, line))
            raise
        except _EvalError as error:
            raise XacroError(str(error), file, line, construct) from None
        except Exception as error:
            raise XacroError('%s: %s' % (type(error).__name__, error), file, line,
                             construct) from None

    def _eval_substitution(self, expression, scope):
        props = self._lookup(scope)

        def lookup(name):
            if name == 'arg':
                return True, self._arg
            if name in self.args:
                return True, self.args[name]
            if name in self.arg_defaults:
                return True, self.arg_defaults[name]
            return props(name)
        return self.interpreter.evaluate(expression, lookup)
