"""The xacro.* functions of expressions: load_yaml (with !degrees and
!radians), abs_filename, message, warning, error, fatal, tokenize."""

import math
import os
import re
import sys

from .bounds import _weight
from .errors import XacroError, _EvalError
from .substitution import _is_real_file
from .values import _dotify
from .xml_io import _read_limited


class _XacroHelpers:
    """The xacro.* functions bound to an expander (mixed into _Expander, whose
    state they use: location, base_dir, interpreter, warn)."""

    def _here(self):
        file = self.location[0]
        return os.path.dirname(os.path.abspath(file)) if _is_real_file(file) else self.base_dir

    def _abs_filename(self, name):
        return name if os.path.isabs(name) else os.path.normpath(os.path.join(self._here(), name))

    def _load_yaml(self, filename):
        try:
            import yaml
        except ImportError:
            raise _EvalError('xacro.load_yaml needs PyYAML, which this python3 cannot import '
                             '(apt-get install python3-yaml)') from None
        path = self._abs_filename(str(filename))
        try:
            data = _read_limited(path)
        except XacroError as error:
            raise _EvalError('cannot load YAML file %s: %s' % (path, error.message)) from None
        interpreter = self.interpreter

        class Loader(yaml.SafeLoader):
            pass

        def angle(to_radians):
            def construct(loader, node):
                text = loader.construct_scalar(node)
                value = interpreter.evaluate(str(text), lambda name: (False, None))
                return math.radians(value) if to_radians else float(value)
            return construct

        Loader.add_constructor('!degrees', angle(True))
        Loader.add_constructor('!radians', angle(False))
        try:
            loaded = yaml.load(data, Loader=Loader)  # noqa: S506 (a SafeLoader)
        except yaml.YAMLError as error:
            raise _EvalError('YAML file %s: %s' % (path, str(error).replace('\n', ' '))) from None
        _weight(loaded, interpreter.budget)
        return _dotify(loaded)

    def _message(self, *args, **_):
        print(' '.join(str(a) for a in args), file=sys.stderr)
        return ''

    def _warning(self, *args, **_):
        file, line = self.location
        self.warn('%s:%s: %s' % (file, line, ' '.join(str(a) for a in args)))
        return ''

    def _error(self, *args, **_):
        file, line = self.location
        self.warn('%s:%s: error: %s' % (file, line, ' '.join(str(a) for a in args)))
        return ''

    def _fatal(self, *args, **_):
        raise _EvalError(' '.join(str(a) for a in args))


def _tokenize(text, sep=',; ', skip_empty=True):
    parts = re.split('[%s]' % re.escape(sep), text)
    return [p for p in parts if p or not skip_empty]
