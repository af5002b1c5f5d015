"""The config schema: generated from the parameter table, and what its errors say."""

import copy

import pytest
import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from beadsim.schema import SCHEMA_FILE, build_schema


def test_schema_file_is_in_sync_with_parameter_table():
    assert yaml.safe_load(SCHEMA_FILE.read_text()) == build_schema(), "run `make schema` and commit the file"


def test_default_and_study_configs_validate(root):
    for path in [root / "config" / "config.yaml", *sorted((root / "config" / "studies").glob("*.yaml")),
                 *sorted((root / "tests" / "configs").glob("*.yaml"))]:
        validate(yaml.safe_load(path.read_text()), str(SCHEMA_FILE))


@pytest.mark.parametrize("edit, words", [
    (lambda c: c["base"].update(beam_powr_W=1), ["beam_powr_W", "Additional properties"]),
    (lambda c: c["base"].update(material="Al"), ["'Al' is not one of ['Ti-Gr2', '308LSi']"]),
    (lambda c: c["base"].update(beam_efficiency=1.5), ["1.5 is greater than the maximum of 1"]),
    (lambda c: c["sweep"][0].update(grid={"wire_angle_deg": [100]}), ["100 is greater than the maximum of 90"]),
    (lambda c: c.update(study="bad name"), ["'bad name' does not match"]),
])
def test_bad_values_are_named(root, edit, words):
    cfg = copy.deepcopy(yaml.safe_load((root / "config" / "config.yaml").read_text()))
    edit(cfg)
    with pytest.raises(WorkflowError) as err:
        validate(cfg, str(SCHEMA_FILE))
    for w in words:
        assert w in str(err.value)
