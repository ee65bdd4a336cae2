"""README.md's Python blocks (<!-- readme-test: python --> above them) run, and print what
their `print(...)  # TEXT` lines say (tests/readme checks that every Python block has one)."""

import os
import re
import subprocess
import sys

import pytest

README = os.path.join(os.path.dirname(__file__), "..", "..", "README.md")


def blocks():
    lines = open(README).read().splitlines()
    out = []
    for i, line in enumerate(lines):
        if line.strip() == "<!-- readme-test: python -->" and i + 1 < len(lines) and lines[i + 1].strip() == "```python":
            end = next(j for j in range(i + 2, len(lines)) if lines[j].strip() == "```")
            out.append((i + 2, lines[i + 2:end]))
    return out


def test_the_readme_has_python_blocks():
    assert len(blocks()) >= 2


@pytest.mark.parametrize("line, code", blocks(), ids=lambda x: str(x) if isinstance(x, int) else "")
def test_a_readme_python_block_runs_and_prints_what_it_says(line, code):
    env = dict(os.environ, HORUS_NAMESPACE=f"readme{os.getpid()}_{line}")
    out = subprocess.run([sys.executable, "-c", "\n".join(code)], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, f"README.md:{line}: {out.stderr}"
    printed = out.stdout.splitlines()
    expected = [m.group(1).strip() for c in code if (m := re.match(r"\s*print\(.*\)\s+#\s(.*)$", c))]
    assert len(printed) == len(expected), f"README.md:{line}: printed {printed}, the comments say {expected}"
    for got, want in zip(printed, expected):
        assert got == want, f"README.md:{line}: printed {got!r}, the README says {want!r}"
