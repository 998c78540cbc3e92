"""The docs' example of a new problem (docs/concepts/ocp.md, Zermelo's) runs, certifies, and stays short."""

from __future__ import annotations

import contextlib
import io
import re

from helpers import REPO


def test_the_zermelo_example_runs_certified_in_at_most_25_lines():
    page = (REPO / "docs/concepts/ocp.md").read_text()
    code = re.search(r"```python\n(.*?)```", page, re.S).group(1)
    assert len([line for line in code.splitlines() if line.strip()]) <= 25
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(code, "docs/concepts/ocp.md", "exec"), {})
    assert printed.getvalue().startswith("converged") and "passed=True" in printed.getvalue()
