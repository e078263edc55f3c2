#!/usr/bin/python3
"""config/spinradar.yaml lists every detector, feature and estimator parameter of
include/spinradar/core/params.hpp with its default (the example must not go stale)."""
import os
import sys

import yaml

root = os.path.normpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..'))
sys.path.insert(0, os.path.join(root, 'cfg'))
import spinradar_params  # noqa: E402

path = os.path.join(root, 'config', 'spinradar.yaml')
with open(path) as f:
    values = yaml.safe_load(f)
errors = []
expected = set()
for name in ('SPINRADAR_DETECTOR_PARAMS', 'SPINRADAR_FEATURE_PARAMS', 'SPINRADAR_ESTIMATOR_PARAMS'):
    for p in spinradar_params.read_list(name):
        expected.add(p['name'])
        if p['name'] not in values:
            errors.append('%s: missing %s (default %r)' % (path, p['name'], p['default']))
        elif values[p['name']] != p['default']:
            errors.append('%s: %s = %r, params.hpp default %r' % (path, p['name'], values[p['name']], p['default']))
for extra in sorted(set(values) - expected):
    errors.append('%s: %s is not a parameter in params.hpp' % (path, extra))
print('\n'.join(errors) if errors else 'config/spinradar.yaml matches params.hpp (%d parameters)' % len(expected))
sys.exit(1 if errors else 0)
