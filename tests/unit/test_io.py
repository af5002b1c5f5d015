"""Atomic outputs: what a reader finds under the final name."""

import json
import math

import numpy as np
import pytest

from beadsim.io import write_json


def test_write_json_is_strict_json(tmp_path):
    """NaN and infinities (a pool edge with no melt, a ratio over zero) become null: Python's json writes them
    as NaN / Infinity, which strict readers (JavaScript, jq) reject; numpy scalars become plain numbers."""
    path = tmp_path / "metrics.json"
    write_json(path, {"a": math.nan, "b": math.inf, "c": -np.inf, "d": np.float64(1.5), "e": [np.int64(2), np.nan],
                      "f": {"g": float("-inf")}})
    text = path.read_text()
    assert "NaN" not in text and "Infinity" not in text
    strict = json.loads(text, parse_constant=lambda name: pytest.fail(f"non-standard constant {name}"))
    assert strict == {"a": None, "b": None, "c": None, "d": 1.5, "e": [2, None], "f": {"g": None}}
    assert [f.name for f in tmp_path.iterdir()] == ["metrics.json"]  # no temporary file left beside it
