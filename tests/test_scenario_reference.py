"""docs/scenario.md against the dataclasses and against the loader (issue 14: a scenario reference).

The reference is generated (``python -m coopctrl.scenario.reference docs/scenario.md``); these
tests fail when the file is stale, or when a key the loader accepts is missing from it (or the
other way round). The loader's own list of keys is read from its error for an unknown key, so it
does not share code with the generator's walk of the dataclasses.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from coopctrl.errors import ScenarioError
from coopctrl.scenario import load_scenario
from coopctrl.scenario.reference import scenario_reference

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "scenario.md"
SCENE = REPO / "scenarios" / "spatial_three_arm_carry.toml"  # has every list section


def _doc_keys() -> list[str]:
    return re.findall(r"^\| `([^`]+)` \|", DOC.read_text(encoding="utf-8"), flags=re.M)


def test_reference_is_up_to_date():
    assert DOC.read_text(encoding="utf-8") == scenario_reference(), (
        "docs/scenario.md differs from the dataclasses: run python -m coopctrl.scenario.reference docs/scenario.md")


def _loader_keys(section: str) -> set[str]:
    """The keys the loader accepts in ``section``, from its message for an unknown key there."""
    path = f"{section}.zz_not_a_key" if section else "zz_not_a_key"
    with pytest.raises(ScenarioError) as info:
        load_scenario(SCENE, {path: 1})
    m = re.search(r"the keys of (?:\[.*\]|the top level) are ([\w, ]+)$", info.value.allowed)
    assert m, info.value.allowed
    return {k.strip() for k in m.group(1).split(",")}


def test_every_key_the_loader_accepts_is_documented_and_no_other():
    doc = _doc_keys()
    assert len(doc) == len(set(doc)), "a key is documented twice"
    sections = {""} | {k.rsplit(".", 1)[0] for k in doc if "." in k}
    documented = set(doc)
    for section in sorted(sections):
        probe = section.replace("[k]", "[0]")
        accepted = _loader_keys(probe)
        in_doc = {k.rsplit(".", 1)[-1] for k in documented if (k.rsplit(".", 1)[0] if "." in k else "") == section}
        assert in_doc == accepted, f"[{section or 'top level'}]: doc {sorted(in_doc)} vs loader {sorted(accepted)}"
    # and every section that holds tables is itself a documented key
    for section in sections - {""}:
        assert section.replace("[k]", "") in {k.replace("[k]", "") for k in documented}, section
