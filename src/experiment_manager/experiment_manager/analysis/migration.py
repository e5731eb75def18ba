"""summary.json's version and the one way an older file is read as the current version
(summary.read takes it): each version's file is made the next's in turn. No rclpy.

Version 2: a feeder run's `first_check` and a calibration's `noise_sd` and `noise_outside`
are written by every run (null where a version-1 file has none). Version 1: a feeder's
throughput, and a time ground without the lognormal's figures.
"""

SCHEMA_VERSION = 2


def migrate(raw: dict) -> dict:
    """A summary.json of any version as the current version's dict."""
    version = raw.get('schema_version', 0)
    if version > SCHEMA_VERSION:
        raise ValueError(f'summary.json: schema_version {version} is newer than this reader '
                         f'({SCHEMA_VERSION})')
    out = raw
    while version < SCHEMA_VERSION:
        step = _FROM[version]
        out = {**out, 'schema_version': version + 1}
        for group in ('experiments', 'repeats'):
            if group in out:
                out[group] = {k: step(v) for k, v in out[group].items()}
        version += 1
    return out


def _from_1(s: dict) -> dict:
    """Version 1 to 2: the keys every run writes since, null where the file has none."""
    if s.get('type') == 'feeder_emptying':
        return {**s, 'first_check': s.get('first_check')}
    if s.get('type') == 'sensitivity' and s.get('calibration'):
        return {**s, 'calibration': [{**c, 'noise_sd': c.get('noise_sd'),
                                      'noise_outside': c.get('noise_outside')}
                                     for c in s['calibration']]}
    return s


def _from_0(s: dict) -> dict:
    """Version 0 (no `schema_version`) to 1: a feeder without its throughput gets an empty
    one; a time ground decided on a lognormal keeps its verdict, bound and reason, not the
    lognormal's figures."""
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


_FROM = {0: _from_0, 1: _from_1}
