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


def test_type_stubs_cover_the_extension_exactly():
    import ast

    import inscribe._inscribe as extension

    stub = ast.parse((SOURCE_DIR / "python" / "inscribe" / "_inscribe.pyi").read_text())
    names = {node.name for node in stub.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}
    names |= {node.target.id for node in stub.body if isinstance(node, ast.AnnAssign)}
    aliases = {"Float64Array", "Int32Array", "Progress", "ProgressBar", "Spheres",
               "HasVerticesAndFaces"}
    public = {name for name in dir(extension) if not name.startswith("__")}
    assert names - aliases == public


def test_every_public_name_is_documented():
    import inscribe

    for name in inscribe.__all__:
        value = getattr(inscribe, name)
        if callable(value):
            assert value.__doc__ and len(value.__doc__) > 20, name
    assert "mesh units" in inscribe.generate.__doc__ and "(N, 4)" in inscribe.generate.__doc__
