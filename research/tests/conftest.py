"""The tool's shared fixtures (tests/conftest.py) for the research's tests too."""

from tests.conftest import *  # noqa: F403 (fixtures)
