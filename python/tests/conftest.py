"""The `skin` binary the tests compare with: $SKIN_BIN, else the workspace's target/release/skin
(built by `cargo test --workspace --release`, the CI step before this suite)."""

from __future__ import annotations

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _binary() -> pathlib.Path:
    path = pathlib.Path(os.environ.get("SKIN_BIN", ROOT / "target" / "release" / "skin"))
    if not path.is_file():
        pytest.fail(f"no skin binary at {path}: build it (cargo build --release -p skin-cli) or set SKIN_BIN")
    return path


class Cli:
    """Runs `skin` with arguments; returns (stdout, stderr)."""

    def __init__(self, path: pathlib.Path):
        self.path = path

    def __call__(self, *args: str) -> tuple[str, str]:
        env = dict(os.environ, RUST_LOG="warn")
        p = subprocess.run([str(self.path), *args], capture_output=True, text=True, env=env, timeout=600)
        assert p.returncode == 0, f"skin {' '.join(args)} failed: {p.stderr}"
        return p.stdout, p.stderr


@pytest.fixture(scope="session")
def cli() -> Cli:
    return Cli(_binary())


@pytest.fixture(autouse=True, scope="session")
def _cache_dir(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Keep the shape-table disk cache of this run out of the user's cache folder."""
    os.environ.setdefault("SKIN_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
