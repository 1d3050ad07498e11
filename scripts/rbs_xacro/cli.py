"""The command line: xacro FILE [name:=value ...] [-o OUT], and the
simulator node's --rbs-reply mode."""

import math
import os
import sys

from .api import expand_file, expand_string, parse_mappings
from .errors import XacroError

USAGE = 'usage: xacro FILE [name:=value ...] [-o OUT]'
_SYNOPSIS = '  xacro FILE [name:=value ...] [-o OUT]'  # the second line of --help


def _reply_mode(argv):
    """--rbs-reply MEMORY_BYTES CPU_SECONDS FILE [name:=value ...]: the node's
    out-of-process expansion (src/io/xacro_process.cc)."""
    out = sys.stdout.buffer
    try:
        if len(argv) < 3:
            raise ValueError('--rbs-reply needs MEMORY_BYTES CPU_SECONDS FILE')
        memory, seconds, path = int(argv[0]), float.fromhex(argv[1]), argv[2]
        args = parse_mappings(argv[3:])
        import resource
        if seconds > 0:
            cpu = max(1, int(math.ceil(seconds)))
            resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))
        if memory > 0:
            resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        urdf = expand_file(path, args, warn=lambda message: None)
        out.write(b'urdf\n' + urdf.encode('utf-8'))
    except MemoryError:
        message = 'out of memory (the limit is %s bytes)' % argv[0]
        out.write(('error %s\n' % message).encode('utf-8'))
    except Exception as error:  # XacroError, a bad argument, an unreadable file ...
        message = str(error) if isinstance(error, (XacroError, ValueError, OSError)) else \
            'internal error: %s: %s' % (type(error).__name__, error)
        out.write(('error %s\n' % message.replace('\n', ';')).encode('utf-8', 'replace'))
    out.flush()
    return 0


def _parse_command_line(argv):
    """(status, files, name:=value words, output file): status is None to go
    on, else the exit status after --help or a usage error (printed)."""
    files, words, output = [], [], None
    index = 0
    while index < len(argv):
        word = argv[index]
        if word in ('-h', '--help'):
            print(USAGE)
            print(_SYNOPSIS)
            return 0, files, words, output
        if word in ('-o', '--output'):
            if index + 1 >= len(argv):
                print('xacro: error: %s needs a file name\n%s' % (word, USAGE), file=sys.stderr)
                return 2, files, words, output
            output = argv[index + 1]
            index += 2
            continue
        if word.startswith('-o') and len(word) > 2:
            output = word[2:].lstrip('=')
        elif word.startswith('--output='):
            output = word[len('--output='):]
        elif word in ('--inorder', '-i', '--legacy-off'):
            pass  # in-order processing is the only one
        elif ':=' in word:
            words.append(word)
        elif word.startswith('-') and word != '-':
            print('xacro: error: unknown option %s\n%s' % (word, USAGE), file=sys.stderr)
            return 2, files, words, output
        else:
            files.append(word)
        index += 1
    if len(files) != 1:
        print('xacro: error: give one FILE\n%s' % USAGE, file=sys.stderr)
        return 2, files, words, output
    return None, files, words, output


def _expand(source, words):
    """The URDF of the file `source` ('-': standard input), or None when the
    error is printed."""
    try:
        args = parse_mappings(words)
        if source == '-':
            return expand_string(sys.stdin.read(), args, os.getcwd())
        return expand_file(source, args)
    except (XacroError, ValueError) as error:
        print('xacro: error: %s' % error, file=sys.stderr)
    except UnicodeDecodeError as error:
        print('xacro: error: %s: not UTF-8 text: %s' % (source, error), file=sys.stderr)
    return None


def _write(urdf, output):
    """The exit status of writing `urdf` to the file `output`, or to stdout."""
    try:
        if output:
            with open(output, 'w', encoding='utf-8') as stream:
                stream.write(urdf)
        else:
            sys.stdout.write(urdf)
            sys.stdout.flush()
    except OSError as error:
        print('xacro: error: cannot write %s: %s' % (output or 'stdout', error.strerror),
              file=sys.stderr)
        return 2
    return 0


def main(argv=None):
    """The command line; returns the exit status (0, or 2 after an error)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == '--rbs-reply':
        return _reply_mode(argv[1:])
    status, files, words, output = _parse_command_line(argv)
    if status is not None:
        return status
    urdf = _expand(files[0], words)
    if urdf is None:
        return 2
    return _write(urdf, output)
