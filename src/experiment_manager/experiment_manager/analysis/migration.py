"""summary.json's version and the one way an older file is read as the current version
(summary.read takes it). No rclpy."""

SCHEMA_VERSION = 1


def migrate(raw: dict) -> dict:
    """A summary.json of any version as the current version's dict. Version 0 (no
    `schema_version`): a feeder without its throughput gets an empty one; a time ground
    decided on a lognormal keeps its verdict, bound and reason, not the lognormal's figures."""
    version = raw.get('schema_version', 0)
    if version > SCHEMA_VERSION:
        raise ValueError(f'summary.json: schema_version {version} is newer than this reader '
                         f'({SCHEMA_VERSION})')
    if version == SCHEMA_VERSION:
        return raw
    out = {**raw, 'schema_version': SCHEMA_VERSION}
    for group in ('experiments', 'repeats'):
        if group in raw:
            out[group] = {k: _migrate_experiment(v) for k, v in raw[group].items()}
    return out


def _migrate_experiment(s: dict) -> dict:
    if s.get('type') != 'feeder_emptying':
        return s
    s = dict(s)
    empty = {'n': 0, 'mean': None, 'min': None, 'max': None, 'std': None}
    s.setdefault('parts_per_hour', empty)
    s.setdefault('parts_per_hour_ci95', [None, None])
    grounds = dict(s['decision'])
    grounds['time'] = {k: v for k, v in grounds['time'].items() if k != 'lognormal'}
    s['decision'] = grounds
    return s
