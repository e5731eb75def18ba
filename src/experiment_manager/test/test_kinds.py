"""The experiment kinds: one class per type in one registry, and every table a later room keeps
per kind (the rooms' import order keeps the class from reaching them) holds every kind that
runs iterations, so that a kind added to the registry and missing from one fails here."""

import os
from types import SimpleNamespace

from experiment_manager import experiment_file
from experiment_manager.analysis import headlines, metrics
from experiment_manager.experiment_file import TYPES
from experiment_manager.experiment_file.kinds import keys_model, kind_of, KINDS
from experiment_manager.experiment_file.plan import groups, plan
from experiment_manager.running import estimate, procedures, sampling
import pytest

CONFIG = os.path.join(os.path.dirname(__file__), '..', 'config')


def test_every_type_is_one_kind_and_every_table_holds_every_kind_that_runs():
    assert list(KINDS) == list(TYPES) or set(KINDS) == set(TYPES)
    assert all(k.name == name for name, k in KINDS.items())
    # each kind reads its entry into a record of its own, which says its type
    assert all(k.record.type == name for name, k in KINDS.items())
    assert len({k.record for k in KINDS.values()}) == len(KINDS)
    running = {name for name, k in KINDS.items() if not k.repeats_others}
    for table in (metrics.SUMMARIES, sampling.DECISIONS, procedures.PROCEDURES,
                  estimate.PRIOR):
        assert set(table) == running
    assert set(headlines.HEADLINES) == set(KINDS)        # every kind has its terminal line
    assert all(keys_model({'type': name}) is k.keys for name, k in KINDS.items())
    assert keys_model({'type': 'bin_racing'}).__name__ == '_AnyExperiment'


def test_a_kind_plans_its_groups_and_names_its_iterations():
    file = experiment_file.load(os.path.join(CONFIG, 'default_experiment.yaml'))
    # the fields plan reads of the summaries before (analysis.summary's records)
    summary = {'bins': SimpleNamespace(best_bin=1), 'sweep': SimpleNamespace(optimal_range=[3, 9])}
    seen = set()
    for exp in file.experiments:
        kind = kind_of(exp)
        seen.add(kind.name)
        assert type(exp) is kind.record
        units = plan(file, exp, summary)
        assert len(units) == len(groups(exp)) * exp.iterations
        assert [u.group for u in units[::exp.iterations]] == groups(exp)
        if kind.repeats_others:
            assert units == []
            continue
        first = units[0]
        assert str(first.iteration + 1) in first.label
        if kind.groups_are_bins:
            assert first.label.startswith(f'bin 1/{len(exp.bins)}')
            assert [u.container for u in units[::exp.iterations]] == list(exp.bins)
        if kind.feeds:
            assert (first.feeder.min_count, first.feeder.max_count) == \
                tuple(exp.optimal_range or (3, 9))
            assert first.container == file.tray
        else:
            assert first.feeder is None
    assert seen == set(KINDS)       # the built-in file shows every kind


def test_an_experiment_says_what_it_takes_from_which_earlier_one():
    from experiment_manager.experiment_file.model import (
        BinStaticExperiment,
        FeederEmptyingExperiment,
        TableSweepExperiment,
    )
    assert BinStaticExperiment(id='bins', iterations=1).taken_from == {}
    assert TableSweepExperiment(id='sweep', iterations=1).sources == ()
    both = FeederEmptyingExperiment(id='feeder', iterations=1, bin_from='bins',
                                    range_from='sweep')
    assert both.taken_from == {'bin_from': 'bins', 'range_from': 'sweep'}
    assert both.sources == ('bins', 'sweep')
    file = experiment_file.load(os.path.join(CONFIG, 'default_experiment.yaml'))
    for exp in file.experiments:     # each names an earlier experiment of the file
        earlier = [e.id for e in file.experiments[:file.experiments.index(exp)]]
        assert all(source in earlier for source in exp.taken_from.values())


@pytest.mark.parametrize('name', sorted(n for n, k in KINDS.items() if not k.repeats_others))
def test_a_kind_s_cost_is_its_parts_times_what_one_iteration_checks(name):
    file = experiment_file.load(os.path.join(CONFIG, 'default_experiment.yaml'))
    exp = file.first_of(name)
    per_part = estimate.units(exp, 10.0) / 10.0
    assert per_part == (len(exp.variants) if KINDS[name].uses_checks else 1)
