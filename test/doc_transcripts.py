# Copyright 2026 squeeze_grasp_ros developers
# SPDX-License-Identifier: Apache-2.0
"""The console transcripts of README.md and docs/*.md: found, run and compared (test_docs.py).

A *transcript* is a fenced block of language ``console``: lines ``$ command`` (continued by a
trailing backslash) each followed by the command's output. Every transcript is either run by
the documentation test or preceded by a visible marker naming why it cannot be, on the line
before its fence (blank lines between are allowed)::

    <!-- untested: REASON -->

Comparison (:func:`compare`): an output line ``...`` stands for any number of lines, and
``...`` inside a line for any text. Every other line must match the command's output line for
line: the same text, and every number equal to the printed precision (the printed value is the
real one rounded; a number printed with 10 or more significant digits, a full ``repr``, is
compared to :data:`REPR_REL_TOL` relative, and a number below 1e-12 in magnitude, round-off
around an exact zero, matches any other such number). Before comparing, the :data:`MASKS`
replace what changes from run to run or machine to machine on both sides; each has a name and
a reason.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PAGES = (REPO / "README.md", *sorted((REPO / "docs").glob("*.md")), REPO / "CONTRIBUTING.md")


@dataclass(frozen=True)
class Command:
    """One ``$ command`` of a transcript and the output printed under it."""

    text: str
    output: tuple[str, ...]


@dataclass(frozen=True)
class Transcript:
    """A ``console`` block: where it is, its commands, and the reason it is not run (if so)."""

    page: Path
    line: int
    commands: tuple[Command, ...]
    untested: str | None

    @property
    def name(self) -> str:
        """``page:line``, the transcript's test id."""
        return f"{self.page.relative_to(REPO)}:{self.line}"


@dataclass(frozen=True)
class Block:
    """Any fenced block: its page, the line of its fence, language and lines."""

    page: Path
    line: int
    language: str
    lines: tuple[str, ...]
    before: str


FENCE = re.compile(r"^\s*```(\S*)\s*$")
UNTESTED = re.compile(r"^<!--\s*untested:\s*(.+?)\s*-->$")


def blocks(page: Path) -> list[Block]:
    """Every fenced block of ``page`` with the last non-blank line before its fence."""
    lines = page.read_text(encoding="utf-8").splitlines()
    found, k = [], 0
    while k < len(lines):
        opening = FENCE.match(lines[k])
        if not opening:
            k += 1
            continue
        end = next(j for j in range(k + 1, len(lines)) if FENCE.match(lines[j]))
        before = next((lines[j].strip() for j in range(k - 1, -1, -1) if lines[j].strip()), "")
        found.append(Block(page, k + 1, opening.group(1), tuple(lines[k + 1:end]), before))
        k = end + 1
    return found


def parse(block: Block) -> Transcript:
    """The commands of a ``console`` block (a trailing backslash continues a command line)."""
    commands: list[Command] = []
    text: str | None = None
    output: list[str] = []
    continued = False
    for line in block.lines:
        if continued:
            text = f"{text} {line.strip()}"
        elif line.startswith("$ "):
            if text is not None:
                commands.append(Command(text, tuple(output)))
            text, output = line[2:].strip(), []
        elif line.strip() or output:
            assert text is not None, f"{block.page}:{block.line}: output before any command"
            output.append(line)
            continue
        else:
            continue
        continued = text.endswith("\\")
        text = text.removesuffix("\\").strip()
    if text is not None:
        commands.append(Command(text, tuple(output)))
    commands = [Command(c.text, _strip_blank_tail(c.output)) for c in commands]
    untested = UNTESTED.match(block.before)
    return Transcript(block.page, block.line, tuple(commands),
                      untested.group(1) if untested else None)


def _strip_blank_tail(lines: tuple[str, ...]) -> tuple[str, ...]:
    """``lines`` without the blank lines that separate it from the next command."""
    end = len(lines)
    while end and not lines[end - 1].strip():
        end -= 1
    return lines[:end]


def transcripts(pages: tuple[Path, ...] = PAGES) -> list[Transcript]:
    """Every ``console`` block of ``pages``, in order."""
    return [parse(b) for page in pages for b in blocks(page) if b.language == "console"]


@dataclass(frozen=True)
class Mask:
    """What changes between runs: ``pattern`` is replaced by ``<name>`` on both sides."""

    name: str
    pattern: str
    reason: str
    unless_after: str = r"(?!)"
    """A match is kept when the text before it ends with this pattern."""


MASKS = (
    Mask("seconds", r"(?<![\w.])\d+(?:\.\d+)?(?:e[-+]?\d+)? ?s\b(?! sim time)",
         "a wall-clock duration: a number of seconds, unless followed by 'sim time' or after "
         "'t=' (simulated times such as '0.700 s sim time' and 't=   0.1040 s' are compared)",
         unless_after=r"t=\s*$"),
    Mask("rate", r"\d+(?:\.\d+)? (?:eval/s|evaluations/s)", "a throughput"),
    Mask("time ratio", r"time x\d+(?:\.\d+)?", "a ratio of two wall-clock times"),
    Mask("minutes", r"\d+(?:\.\d+)? min\b", "an estimated duration"),
    Mask("seconds column", r"(?<=D\d)( +)\d+\.\d+$",
         "the wall-clock column after the event counts of a --compare-models row"),
    Mask("time_s row", r"^time_s\s.*$", "the wall-clock quantiles of sweep-report"),
    Mask("precompute_time", r"precompute_time=[0-9.e-]+", "a wall-clock duration in a message"),
    Mask("run mode", r"(?<=sim time; )(?:attached to running nodes|one process, \w+|[\w ]*"
         r"processes[\w ]*)(?=, plan from)",
         "how `run` ran the nodes: a launch transcript's run is attached to the launched nodes, "
         "its equivalent runs them in one process"),
    Mask("pid", r"pid \[\d+\]", "a process id"),
    Mask("run namespace", r"run_\d+_[0-9a-f]{8}",
         "a run's own namespace: its process id and 8 random hexadecimal digits"),
    Mask("log stamp", r"\[\d{9,}\.\d+\]", "the wall-clock stamp of a ROS log line"),
    Mask("log folder", r"/\S*\.ros/log/\S+", "a dated log folder of ros2 launch"),
    Mask("goal id", r"\b[0-9a-f]{32}\b", "a random action goal id"),
    Mask("temporary path", r"/tmp/[^\s'\",)]*", "a temporary folder"),
)
"""Everything masked before comparing, in order."""

REPR_REL_TOL = 1e-8
"""How far a full ``repr`` may move between machines. The ring's stiffness and forces come out
of a banded Cholesky of a system with a condition number near 1e7 (stiff axial against soft
bending fibres): two hosts of the project's machine kind, whose OpenBLAS picked different
kernels for their CPUs, printed them 2.3e-9 apart (relative)."""
NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
SLOT = "\x00"


def masked(line: str) -> str:
    """``line`` with every :data:`MASKS` match replaced by ``<name>`` (marked as a slot)."""
    for mask in MASKS:
        line = re.sub(mask.pattern, lambda m, mask=mask: (
            m.group() if re.search(mask.unless_after, m.string[:m.start()])
            else f"{SLOT}<{mask.name}>{SLOT}"), line)
    return line


def _pattern(expected: str) -> tuple[re.Pattern[str], list[str]]:
    """A regex for the masked expected line, with one group per printed number."""
    parts, numbers = [], []
    for k, piece in enumerate(masked(expected).split(SLOT)):
        if k % 2:  # a masked slot: matches the same slot on the other side
            parts.append(re.escape(piece))
            continue
        for j, chunk in enumerate(piece.split("...")):
            if j:
                parts.append(".*?")
            last = 0
            for m in NUMBER.finditer(chunk):
                parts.append(re.escape(chunk[last:m.start()]))
                parts.append(f"({NUMBER.pattern})")
                numbers.append(m.group())
                last = m.end()
            parts.append(re.escape(chunk[last:]))
    return re.compile("".join(parts)), numbers


def number_matches(printed: str, actual: str) -> bool:
    """Whether ``actual`` rounds to ``printed`` (see the module docstring)."""
    x, a = float(printed), float(actual)
    if abs(x) < 1e-12 and abs(a) < 1e-12:
        return True
    mantissa, _, exponent = printed.lower().lstrip("+-").partition("e")
    digits = mantissa.replace(".", "").lstrip("0")
    if len(digits) >= 10:
        return math.isclose(x, a, rel_tol=REPR_REL_TOL, abs_tol=1e-15)
    decimals = len(mantissa.partition(".")[2])
    unit = 10.0 ** (int(exponent or 0) - decimals)
    return abs(x - a) <= 0.5 * unit * (1 + 1e-9) + 1e-15 * abs(x)


def line_matches(expected: str, actual: str) -> bool:
    """Whether one output line matches its expected text (masks, ``...``, numbers)."""
    pattern, numbers = _pattern(expected)
    found = pattern.fullmatch(masked(actual).replace(SLOT, ""))
    if found is None:
        return False
    return all(number_matches(p, a) for p, a in zip(numbers, found.groups()))


def json_matches(expected: object, actual: object, path: str = "") -> str | None:
    """None when the parsed JSON ``actual`` matches ``expected`` (numbers as in
    :func:`number_matches`, from their shortest repr), else the first differing path.
    """
    if isinstance(expected, dict) and isinstance(actual, dict):
        if list(expected) != list(actual):
            return f"{path or '(top)'}: keys {list(expected)} != {list(actual)}"
        return next((d for k in expected
                     if (d := json_matches(expected[k], actual[k], f"{path}.{k}"))), None)
    if isinstance(expected, list) and isinstance(actual, list):
        if len(expected) != len(actual):
            return f"{path}: {len(expected)} items != {len(actual)}"
        return next((d for k, (e, a) in enumerate(zip(expected, actual))
                     if (d := json_matches(e, a, f"{path}[{k}]"))), None)
    numbers = (int, float)
    if (isinstance(expected, numbers) and isinstance(actual, numbers)
            and not isinstance(expected, bool) and not isinstance(actual, bool)):
        return None if number_matches(repr(expected), repr(actual)) else \
            f"{path}: {expected!r} != {actual!r}"
    return None if expected == actual else f"{path}: {expected!r} != {actual!r}"


ELIDED = "..."
"""An elided value of an abridged JSON example (:func:`abridged_json`)."""


def abridged_json(text: str) -> object:
    """An abridged JSON example as data: ``{...}`` or ``...`` after a key is an elided value
    (:data:`ELIDED`), and ``, ...`` closing a list or an object an elided rest, kept as a last
    item ``"..."`` or a last key ``"..."``.
    """
    text = text.replace("{...}", json.dumps(ELIDED))
    text = re.sub(r":\s*\.\.\.(?=\s*[,}\]])", f": {json.dumps(ELIDED)}", text)
    text = re.sub(r",\s*\.\.\.\s*\]", f", {json.dumps(ELIDED)}]", text)
    text = re.sub(r",\s*\.\.\.\s*\}", f", {json.dumps(ELIDED)}: {json.dumps(ELIDED)}}}", text)
    return json.loads(text)


def abridged_json_matches(expected: object, actual: object, path: str = "") -> str | None:
    """None when ``actual`` matches the abridged example ``expected`` (:func:`abridged_json`):
    an elided value matches anything; an object without an elided rest has exactly the
    actual keys in their order, one with it some of them in their order; a list with an
    elided rest is a prefix of the actual one. Everything else as :func:`json_matches`.
    """
    if expected == ELIDED:
        return None
    if isinstance(expected, dict) and isinstance(actual, dict):
        keys = [k for k in expected if k != ELIDED]
        order = [k for k in actual if k in keys]
        if keys != (order if ELIDED in expected else list(actual)):
            return f"{path or '(top)'}: keys {keys} != {list(actual)}"
        return next((d for k in keys
                     if (d := abridged_json_matches(expected[k], actual[k], f"{path}.{k}"))),
                    None)
    if isinstance(expected, list) and isinstance(actual, list):
        shown = expected[:-1] if expected and expected[-1] == ELIDED else expected
        if len(shown) > len(actual) or (shown is expected and len(shown) != len(actual)):
            return f"{path}: {len(expected)} items against {len(actual)}"
        return next((d for k, (e, a) in enumerate(zip(shown, actual))
                     if (d := abridged_json_matches(e, a, f"{path}[{k}]"))), None)
    return json_matches(expected, actual, path)


def compare(expected: tuple[str, ...], actual: list[str]) -> str | None:
    """None when ``actual`` matches ``expected``, else what differs (first mismatch)."""
    actual = [line.rstrip() for line in actual]
    while actual and not actual[-1]:
        actual.pop()
    if expected and expected[0].startswith("{") and actual and actual[0].startswith("{"):
        text = "\n".join(expected)
        try:
            wanted, matches = json.loads(text), json_matches
        except json.JSONDecodeError:  # an abridged example (a value elided as ...)
            try:
                wanted, matches = abridged_json(text), abridged_json_matches
            except json.JSONDecodeError:
                wanted = None  # not JSON even so: compared line by line
        if wanted is not None:
            found = matches(wanted, json.loads("\n".join(actual)))
            return None if found is None else f"JSON differs at {found}"

    def match(i: int, j: int) -> int | None:
        """Index in ``expected`` where matching failed (len(expected) if it never does)."""
        while i < len(expected):
            if expected[i].strip() == "...":
                return max((match(i + 1, k) for k in range(j, len(actual) + 1)),
                           key=lambda r: len(expected) + 1 if r is None else r)
            if j >= len(actual) or not line_matches(expected[i].rstrip(), actual[j]):
                return i
            i, j = i + 1, j + 1
        return None if j == len(actual) else len(expected)

    failed = match(0, 0)
    if failed is None:
        return None
    shown = "\n".join(f"    {line}" for line in actual) or "    (nothing)"
    where = (f"expected line {failed + 1}: {expected[failed]!r}" if failed < len(expected)
             else "the output goes on past the transcript")
    return f"{where}\n  actual output:\n{shown}"
