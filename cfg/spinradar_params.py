"""Reads the X-macro parameter lists of include/spinradar/core/params.hpp (the single definition
of every pipeline parameter) and adds them to a dynamic_reconfigure ParameterGenerator.

Each list entry is one line `X(type, name, default, min, max, "unit", "doc")`. A string
parameter whose doc ends in ": a, b or c" becomes an enum of those choices.
"""
import os
import re

HEADER = os.path.normpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), '..',
                                       'include', 'spinradar', 'core', 'params.hpp'))

_ENTRY = re.compile(r'^\s*X\(\s*(?P<type>[\w:]+)\s*,\s*(?P<name>\w+)\s*,\s*'
                    r'(?P<default>"[^"]*"|[^,]+?)\s*,\s*(?P<min>[^,]+?)\s*,\s*(?P<max>[^,]+?)\s*,\s*'
                    r'"(?P<unit>[^"]*)"\s*,\s*"(?P<doc>[^"]*)"\s*\)\s*\\?\s*$')
_TYPES = {'double': 'double', 'float': 'double', 'int': 'int', 'bool': 'bool', 'std::string': 'str'}


def _number(text, kind, where):
    text = text.strip().rstrip('fF')
    try:
        return int(float(text)) if kind == 'int' else float(text)
    except ValueError:
        raise ValueError('%s: cannot read number %r' % (where, text))


def read_list(list_name, header=HEADER):
    """Entries of `#define <list_name>(X)` as dicts: type, name, default, min, max, unit, doc."""
    with open(header) as f:
        lines = f.read().split('\n')
    start = None
    for i, line in enumerate(lines):
        if re.match(r'^\s*#\s*define\s+%s\(X\)' % re.escape(list_name), line):
            start = i
            break
    if start is None:
        raise ValueError('%s: no list %s' % (header, list_name))
    params = []
    i = start
    while lines[i].rstrip().endswith('\\'):
        i += 1
        where = '%s:%d' % (header, i + 1)
        m = _ENTRY.match(lines[i])
        if not m:
            raise ValueError('%s: not an X(type, name, default, min, max, "unit", "doc") line: %r'
                             % (where, lines[i]))
        kind = _TYPES.get(m.group('type'))
        if kind is None:
            raise ValueError('%s: unsupported parameter type %r' % (where, m.group('type')))
        p = dict(type=kind, name=m.group('name'), unit=m.group('unit'), doc=m.group('doc'),
                 min=None, max=None)
        d = m.group('default')
        if kind == 'str':
            p['default'] = d.strip('"')
        elif kind == 'bool':
            p['default'] = d.strip() == 'true'
        else:
            p['default'] = _number(d, kind, where)
            p['min'] = _number(m.group('min'), kind, where)
            p['max'] = _number(m.group('max'), kind, where)
        params.append(p)
    return params


def choices(param):
    """Fixed choices of a string parameter ("...: a, b or c"), or None."""
    if param['type'] != 'str' or ':' not in param['doc']:
        return None
    tail = param['doc'].rsplit(':', 1)[1]
    items = [s.strip() for s in re.split(r',|\bor\b', tail) if s.strip()]
    if len(items) < 2 or not all(re.match(r'^[A-Za-z0-9_]+$', s) for s in items):
        return None
    return items if param['default'] in items else None


def description(param):
    """dynamic_reconfigure forbids quotes in descriptions."""
    text = param['doc'] + (' [%s]' % param['unit'] if param['unit'] else '')
    return text.replace('"', '').replace("'", '')


def add_params(gen, list_name, level, only=None, exclude=()):
    """Adds the entries of one list to `gen` (filtered by name), all with the given level bit."""
    added = []
    for p in read_list(list_name):
        if (only is not None and p['name'] not in only) or p['name'] in exclude:
            continue
        edit_method = ''
        opts = choices(p)
        if opts:
            consts = [gen.const('%s_%s' % (p['name'], c), 'str', c, '%s = %s' % (p['name'], c))
                      for c in opts]
            edit_method = gen.enum(consts, description(p))
        gen.add(p['name'], p['type'], level, description(p), p['default'], p['min'], p['max'],
                edit_method)
        added.append(p['name'])
    if only is not None and set(only) - set(added):
        raise ValueError('%s: %s has no parameter %s' % (HEADER, list_name,
                                                          ', '.join(sorted(set(only) - set(added)))))
    return added
