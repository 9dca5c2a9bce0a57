"""The plan file's text (planfile/format.py ``plan_text``): the JSON value ``json.dumps`` writes, a
configuration per line."""

from __future__ import annotations

import json
import math
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mrgc.planfile.format import plan_text

scalars = st.none() | st.booleans() | st.integers(-(10**12), 10**12) | st.floats(allow_nan=False) | st.text()
values = st.recursive(
    scalars,
    lambda inner: (
        st.lists(inner, max_size=5)
        | st.dictionaries(st.text(max_size=8) | st.integers(-5, 5) | st.booleans(), inner, max_size=5)
    ),
    max_leaves=40,
)


@settings(max_examples=300, deadline=None)
@given(values)
def test_the_text_reads_back_as_what_json_dumps_writes(doc: Any) -> None:
    text = plan_text(doc)
    assert text.endswith("\n") and json.loads(text) == json.loads(json.dumps(doc))


@settings(max_examples=100, deadline=None)
@given(st.lists(st.lists(st.floats(allow_nan=False, allow_infinity=False), min_size=7, max_size=7), min_size=1))
def test_each_configuration_sits_on_one_line_with_its_floats_as_written(configs: list[list[float]]) -> None:
    text = plan_text({"configs": {"pick": configs}})
    lines = text.splitlines()
    assert len(lines) == len(configs) + 6  # {, "configs": {, "pick": [, one line per configuration, ], }, }
    rows = [json.loads(line.strip().rstrip(",")) for line in lines[3 : 3 + len(configs)]]
    assert rows == configs and all(
        math.copysign(1, a) == math.copysign(1, b) for r, c in zip(rows, configs) for a, b in zip(r, c)
    )


def test_a_key_json_cannot_write_is_refused_as_json_dumps_refuses_it() -> None:
    for doc in ({(1, 2): 3}, {"a": [{frozenset(): 1}]}):
        with pytest.raises(TypeError):
            json.dumps(doc)
        with pytest.raises(TypeError):
            plan_text(doc)
