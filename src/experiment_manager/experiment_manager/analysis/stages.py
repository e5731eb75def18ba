"""Why parts were turned down: per experiment, over every check it made, how many of the parts
in the container each stage of the validity check stopped (candidacy, placeability, container
collision, neighbour collision) and how many were valid, from `checks.csv`; and the words of
the report's section on it, naming the stage that stops most."""

from collections.abc import Iterable

from .wording import pct, table

# stage: (the count of checks.csv that reached it, the count that passed it)
STAGES = {'candidacy': ('in_container', 'candidates'),
          'placeability': ('candidates', 'placeable'),
          'container collision': ('placeable', 'container_free'),
          'neighbour collision': ('container_free', 'valid')}


def turned_down(rows: Iterable[dict]) -> dict[str, dict[str, int]]:
    """Per experiment (in the order first seen): parts checked in the container, parts each
    stage stopped, and parts valid, summed over its checks (rows of checks.csv, typed)."""
    out: dict[str, dict[str, int]] = {}
    for r in rows:
        counts = {'in_container': r['checked'] - r['outside'], 'candidates': r['candidates'],
                  'placeable': r['placeable'], 'container_free': r['container_free'],
                  'valid': r['valid']}
        total = out.setdefault(r['experiment'], dict.fromkeys(
            ['in_container', *STAGES, 'valid'], 0))
        total['in_container'] += counts['in_container']
        total['valid'] += counts['valid']
        for stage, (reached, passed) in STAGES.items():
            total[stage] += counts[reached] - counts[passed]
    return out


def lines(stops: dict[str, dict[str, int]]) -> list[str]:
    """The report's section: a row per experiment, the shares of the parts in the container,
    and the stage that stops most."""
    if not stops:
        return []
    rows, said = [], []
    for exp_id, s in stops.items():
        parts = s['in_container']
        share = [s[stage] / parts if parts else 0.0 for stage in STAGES]
        rows.append([f'`{exp_id}`', parts, *[pct(v) for v in share],
                     pct(s['valid'] / parts if parts else 0.0)])
        if parts and max(share) > 0:
            worst = max(STAGES, key=lambda stage: s[stage])
            said.append(f'`{exp_id}`: {worst} stops most, {pct(s[worst] / parts)} of the parts '
                        'in the container')
    return (['', '## Why parts were turned down', '',
             'Over every check of each experiment, the share of the parts in the container that '
             'each stage stopped (a part stops at the first stage it fails; a bin_static '
             'experiment checks no neighbours: the static bin analysis skips them):', '']
            + table(['experiment', 'parts checked', *STAGES, 'valid'], rows)
            + ([''] + [f'- {s}' for s in said] if said else []))
