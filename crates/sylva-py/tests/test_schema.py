"""`sylva.schema`: every model's genome field by field, as the studio and docs/genomes.md
show it."""

from __future__ import annotations

import pytest

import sylva

KEYS = {"path", "group", "meaning", "kind", "unit", "shapes", "optional"}


@pytest.mark.parametrize("model", sorted(sylva.models()))
def test_every_field_is_described_and_found_in_a_genome(model):
    schema = sylva.schema(model)
    assert schema["fields"], model
    genome = sylva.Genome.random(model, 3)
    for field in schema["fields"]:
        assert KEYS <= field.keys(), field
        assert field["meaning"].endswith("."), field["path"]
        if "[]" not in field["path"] and not field["optional"]:
            genome[field["path"]]  # a KeyError names the field the genome lacks


def test_a_number_has_its_range_and_unit():
    (height,) = [f for f in sylva.schema("grown")["fields"] if f["path"] == "parameters.height"]
    assert (height["kind"], height["min"], height["max"], height["unit"]) == ("number", 1.0, 40.0, " m")
    assert height["shapes"] and height["step"] == 0.1 and not height["log"]


def test_structures_are_named():
    assert [s["editor"] for s in sylva.schema("lsystem")["structures"]] == ["rules", "rules"]
    assert [s["path"] for s in sylva.schema("automata")["structures"]] == ["program"]


def test_an_unknown_model_is_an_input_error_naming_it():
    with pytest.raises(sylva.InputError, match='model: no model is named "oak"; expected one of bintree'):
        sylva.schema("oak")


def test_with_field_takes_the_schemas_paths_and_names_the_range():
    genome = sylva.Genome.load(str(__import__("pathlib").Path(__file__).resolve().parents[3]
                                   / "examples" / "plantmaker" / "tulip.json"))
    assert genome.with_field("branches[0].waves", 3)["branches.0.waves"] == 3
    with pytest.raises(sylva.InputError, match=r"`branches\[0\]\.waves` takes a whole number from 1 to 16, not 40"):
        genome.with_field("branches[0].waves", 40)
