"""Shared fixtures: where the shared test data is, and a private cache directory."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

# The alight pytest plugin is registered by its pytest11 entry point once the package is
# installed; a checkout whose installed copy predates it loads it from here instead.
from importlib.metadata import entry_points as _entry_points

pytest_plugins = ["pytester"]
if not any(ep.name == "alight" for ep in _entry_points(group="pytest11")):
    pytest_plugins.append("app.pytest_plugin")

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """../shared/data beside the checkout (CI clones main with shared/ beside it)."""
    if not SHARED_DATA.is_dir():
        pytest.fail(f"shared test data not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session", autouse=True)
def _private_cache(tmp_path_factory):
    """Keep the tests' LUT cache away from the user's own cache directory."""
    old = os.environ.get("ALIGHT_CACHE_DIR")
    os.environ["ALIGHT_CACHE_DIR"] = str(tmp_path_factory.mktemp("alight-cache"))
    yield
    if old is None:
        os.environ.pop("ALIGHT_CACHE_DIR", None)
    else:
        os.environ["ALIGHT_CACHE_DIR"] = old
