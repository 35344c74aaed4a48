# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The examples in the docstrings run (scikit-fem style), and every public function of the
front door :mod:`squeeze_grasp_ros.api` is called in at least one of them.
"""
from __future__ import annotations

import doctest
import importlib
import inspect
import pkgutil
import re

import pytest

import squeeze_grasp_ros
from squeeze_grasp_ros import api
from squeeze_grasp_ros.extras import install_hint

EXEMPT: dict[str, str] = {
    "extract_outline": "needs the perception extra (scikit-image), which the core suite may "
                       "lack; docs/perception.md's example of it runs in test_docs.py, and "
                       "test_perception_extract.py runs it",
}
"""Public functions without their own example, and why."""


def package_modules() -> list[str]:
    return sorted(m.name for m in pkgutil.walk_packages(squeeze_grasp_ros.__path__,
                                                        "squeeze_grasp_ros."))


NEEDS_EXTRA: dict[str, str] = {}
"""Modules that cannot be imported here because an extra is not installed -> why."""


def examples(module_name: str) -> list[doctest.DocTest]:
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as error:
        hint = install_hint(error.name or "")
        if hint is None:
            raise
        NEEDS_EXTRA[module_name] = f"needs {error.name}, which is not installed: {hint}"
        return []
    return [t for t in doctest.DocTestFinder().find(module, module_name) if t.examples]


MODULES_WITH_EXAMPLES = [m for m in package_modules() if examples(m)]


def test_there_are_examples_to_run():
    assert len(MODULES_WITH_EXAMPLES) + len(NEEDS_EXTRA) >= 12


@pytest.mark.parametrize("module_name", MODULES_WITH_EXAMPLES + sorted(NEEDS_EXTRA))
def test_examples(module_name):
    if module_name in NEEDS_EXTRA:
        pytest.skip(NEEDS_EXTRA[module_name])
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in examples(module_name):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed"


def test_every_public_function_has_an_example():
    code = "\n".join(ex.source for m in MODULES_WITH_EXAMPLES for t in examples(m)
                     for ex in t.examples)
    functions = [name for name in api.__all__
                 if inspect.isfunction(getattr(api, name)) and name not in EXEMPT]
    missing = [name for name in functions if not re.search(rf"\b{name}\(", code)]
    assert len(functions) > 15 and missing == []


def test_the_front_door_exports_what_it_lists():
    assert len(api.__all__) == len(set(api.__all__)) >= 30
    assert all(hasattr(api, name) for name in api.__all__)


def test_the_readme_example_runs_and_imports_only_the_front_door(capsys):
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Python API"):]
    code = section[section.index("```python\n") + 10:section.index("```\n", 10)]
    imports = [line for line in code.splitlines() if line.startswith(("import ", "from "))]
    assert imports and all(line.startswith("from squeeze_grasp_ros.api import ")
                           for line in imports)
    assert len(code.strip().splitlines()) <= 5
    exec(compile(code, "README.md", "exec"), {})
    printed = capsys.readouterr().out.splitlines()
    assert printed and all(line.split()[0] in "ABCD" for line in printed)


def test_the_readme_names_only_enums_the_front_door_exports():
    """The README's Python API section names the domain enums as importable from the API,
    including the codes (effects, ring limits) that a scene or ``ring_grasp`` hands back.
    """
    from pathlib import Path

    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Python API"):readme.index("## The CLI")]
    sentence = section[section.index("The domain words are enums"):]
    named = re.findall(r"`([A-Z][A-Za-z]+)`", sentence[:sentence.index("...")])
    assert {"Finger", "Effect"} <= set(named)
    assert [name for name in named if name not in api.__all__] == []
    from squeeze_grasp_ros.mechanics.vocabulary import Effect, RingLimit
    assert api.Effect is Effect and api.RingLimit is RingLimit
