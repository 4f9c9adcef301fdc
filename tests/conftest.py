"""Shared fixtures: where the shared test data is, and a private cache directory."""

from __future__ import annotations

import os

# The alight pytest plugin is registered by its pytest11 entry point once the package is
# installed; a checkout whose installed copy predates it loads it from here instead.
from importlib.metadata import entry_points as _entry_points
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]
if not any(ep.name == "alight" for ep in _entry_points(group="pytest11")):
    pytest_plugins.append("alight.frontends.pytest_plugin")

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """../shared/data beside the checkout (CI clones main with shared/ beside it)."""
    if not SHARED_DATA.is_dir():
        pytest.fail(f"shared test data not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session", autouse=True)
def _private_cache_and_config(tmp_path_factory):
    """Keep the tests' caches and the editor's session away from the user's own folders."""
    old = {k: os.environ.get(k) for k in ("ALIGHT_CACHE_DIR", "ALIGHT_CONFIG_DIR", "ALIGHT_DATA_DIR")}
    os.environ["ALIGHT_CACHE_DIR"] = str(tmp_path_factory.mktemp("alight-cache"))
    os.environ["ALIGHT_CONFIG_DIR"] = str(tmp_path_factory.mktemp("alight-config"))
    os.environ["ALIGHT_DATA_DIR"] = str(tmp_path_factory.mktemp("alight-data"))   # the editor's library
    yield
    for k, v in old.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v
