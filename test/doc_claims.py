# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""Reading what README.md and docs/ state, for the tests that compare it with the product
(test_docs_claims.py: names, tables, constants; test_docs_results.py: results of runs).

The console transcripts are test_docs.py's (doc_transcripts.py); these read prose, tables and
the blocks that are no transcripts.
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import re

import yaml
from doc_transcripts import REPO, blocks


def page_text(name: str) -> str:
    """A page (``README.md``, ``CONTRIBUTING.md`` or ``docs/NAME``), whitespace normalised."""
    path = REPO / name if name in ("README.md", "CONTRIBUTING.md") else REPO / "docs" / name
    return " ".join(path.read_text(encoding="utf-8").split())


def yaml_block(name: str, first: str) -> dict:
    """The ```yaml block of ``docs/NAME`` whose first line starts with ``first``, parsed."""
    found = [b for b in blocks(REPO / "docs" / name)
             if b.language == "yaml" and b.lines and b.lines[0].startswith(first)]
    assert len(found) == 1, f"docs/{name}: {len(found)} yaml blocks start with {first!r}"
    return yaml.safe_load("\n".join(found[0].lines))


def shipped(path: str) -> dict:
    """A shipped YAML file under config/, parsed."""
    return yaml.safe_load((REPO / "config" / path).read_text(encoding="utf-8"))


def stated(name: str, pattern: str) -> list[float]:
    """The numbers ``pattern`` captures on a page (thousands separators dropped)."""
    found = re.search(pattern, page_text(name))
    assert found, f"{name} no longer states {pattern!r}"
    return [float(x.replace(",", "")) for x in found.groups()]


def cli_json(words: list[str], folder) -> dict:
    """``squeeze-grasp WORDS --json`` run in this process from ``folder``, its JSON."""
    from squeeze_grasp_ros import cli

    out, cwd = io.StringIO(), os.getcwd()
    os.chdir(folder)
    try:
        with contextlib.redirect_stdout(out):
            code = cli.main([*words, "--json"])
    finally:
        os.chdir(cwd)
    assert code == 0, (words, out.getvalue())
    return json.loads(out.getvalue())


FOAM_SQUARE = str(REPO / "config" / "scenes" / "foam_square.yaml")
