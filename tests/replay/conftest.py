"""The replay suite's option: --update-reference rewrites the stored reference outputs from
the build under test (only when the component changed on purpose; say so in the commit)."""

import pytest


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.getgroup("autodrive replay").addoption(
        "--update-reference",
        action="store_true",
        help="rewrite tests/replay/data/*_reference.json from this build instead of checking",
    )
