"""summary.json as a typed, versioned model: the schema published in docs is the model's, a run's
summary.json validates against it by a reader independent of the model (jsonschema), a summary
of version 0 or 1 is read through the one migration, and a summary that breaks the model is refused
where it is made."""

import copy
import json
import os

from experiment_manager.analysis import summary
import jsonschema
import pydantic
import pytest

DOCS = os.path.join(os.path.dirname(__file__), '..', '..', '..', 'docs')
PUBLISHED = os.path.join(DOCS, 'summary.schema.json')


def _written(small) -> dict:
    with open(os.path.join(small[0], 'summary.json'), encoding='utf-8') as f:
        return json.load(f)


def test_the_published_schema_is_the_models():
    with open(PUBLISHED, encoding='utf-8') as f:
        published = f.read()
    assert published == summary.schema_text(), (
        "docs/summary.schema.json is not the model's: write it again with "
        '`python -m experiment_manager.analysis.summary --schema docs/summary.schema.json`')


def test_a_runs_summary_validates_against_the_published_schema(small):
    written = _written(small)
    with open(PUBLISHED, encoding='utf-8') as f:
        schema = json.load(f)
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(written, schema, cls=jsonschema.Draft202012Validator)
    assert written['schema_version'] == summary.SCHEMA_VERSION
    # the schema says something: a key it does not know and a wrong type are refused
    for broken in ({**written, 'colour': 'red'}, {**written, 'seed': 'seven'}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(broken, schema, cls=jsonschema.Draft202012Validator)


def test_the_model_holds_every_key_of_a_summary_as_written(small):
    written = _written(small)
    typed = summary.validate(written)
    assert typed.model_dump(mode='json', by_alias=True, exclude_unset=True) == written
    assert [k for k, _ in typed.of_type('table_sweep')] == ['sweep']
    assert typed.last('feeder_emptying').decision.time.verdict in (
        'FEASIBLE', 'NOT FEASIBLE', 'UNDECIDED')


def test_a_version_0_summary_is_read_through_the_migration(small, tmp_path):
    old = copy.deepcopy(_written(small))
    del old['schema_version']
    feeder = old['experiments']['feeder']
    del feeder['parts_per_hour'], feeder['parts_per_hour_ci95']      # before the cell's time
    feeder['decision']['time']['lognormal'] = {'mu': 7.1, 'sigma': 0.02}
    path = tmp_path / 'summary.json'
    path.write_text(json.dumps(old))
    with pytest.raises(pydantic.ValidationError):
        summary.validate(old)               # as it is, version 0 is not the current model
    typed = summary.read(str(path))
    assert typed.schema_version == summary.SCHEMA_VERSION
    assert typed.experiments['feeder'].parts_per_hour.n == 0
    assert typed.experiments['feeder'].decision.time == summary.validate(
        _written(small)).experiments['feeder'].decision.time
    with pytest.raises(ValueError, match='schema_version 3 is newer than this reader'):
        summary.migrate({**old, 'schema_version': 3})


def test_a_version_1_summary_is_read_through_the_migration(small, tmp_path):
    # version 1's feeder runs had no first check; the rest is today's
    old = copy.deepcopy(_written(small))
    old['schema_version'] = 1
    del old['experiments']['feeder']['first_check']
    path = tmp_path / 'summary.json'
    path.write_text(json.dumps(old))
    with pytest.raises(pydantic.ValidationError, match='first_check'):
        summary.validate(old)               # as it is, version 1 is not the current model
    typed = summary.read(str(path))
    assert typed.schema_version == 2 == summary.SCHEMA_VERSION
    assert typed.experiments['feeder'].first_check is None
    now = summary.validate(_written(small))
    assert typed.experiments['sweep'] == now.experiments['sweep']
    assert typed.experiments['feeder'].decision == now.experiments['feeder'].decision


def test_a_summary_that_breaks_the_model_is_never_made(small, tmp_path):
    """The metrics make each record typed (a wrong value is refused where it is made, naming
    its field), and what a run writes is its Summary's own text."""
    directory, made = small
    sweep = made.experiments['sweep']
    with pytest.raises(pydantic.ValidationError, match='n_star'):
        type(sweep)(**{**sweep.model_dump(exclude_unset=True), 'n_star': 'many'})
    nan = made.requirements.model_copy(update={'success_rate': float('nan')})
    with pytest.raises(ValueError, match='Out of range float values'):    # JSON has no NaN
        made.model_copy(update={'requirements': nan}).json_text()
    with open(os.path.join(directory, 'summary.json'), encoding='utf-8') as f:
        assert f.read() == made.json_text()
