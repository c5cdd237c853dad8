"""Runs every ```python example of docs/python.md, from the source tree, with a real server for
the ones that call the service (INSCRIBE_SERVER)."""

import os
import re

import pytest

from conftest import SOURCE_DIR

EXAMPLES = re.findall(r"```python\n(.*?)```", (SOURCE_DIR / "docs" / "python.md").read_text(),
                      re.S)


def test_the_page_has_its_examples():
    assert len(EXAMPLES) >= 4


@pytest.mark.parametrize("index", range(len(EXAMPLES)))
def test_example_runs(index, server, monkeypatch):
    monkeypatch.chdir(SOURCE_DIR)
    monkeypatch.setenv("INSCRIBE_SERVER", server.address)
    exec(compile(EXAMPLES[index], f"docs/python.md example {index + 1}", "exec"), {})
