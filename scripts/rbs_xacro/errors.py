"""The exceptions: XacroError, the one error of a bad description, and
_EvalError, an expression's own error that its caller places."""


class XacroError(Exception):
    """A description that cannot be expanded: where, in which construct, why.

    str() is 'FILE:LINE: CONSTRUCT: MESSAGE', then one indented line for
    each macro call, include or property that led there."""

    def __init__(self, message, file=None, line=None, construct=None):
        super().__init__(message)
        self.message = message
        self.file = file
        self.line = line
        self.construct = construct
        self.trace = []

    def __str__(self):
        head = ''
        if self.file:
            head = '%s:%s: ' % (self.file, self.line) if self.line else '%s: ' % self.file
        if self.construct:
            head += self.construct + ': '
        trace = self.trace
        if len(trace) > 12:  # a recursion: its first and last steps tell the story
            trace = trace[:8] + ['... %d more ...' % (len(trace) - 11)] + trace[-3:]
        return head + self.message + ''.join('\n  ' + entry for entry in trace)


class _EvalError(Exception):
    """An expression's own error, placed by the caller."""
