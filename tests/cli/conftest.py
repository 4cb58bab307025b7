"""Every command test starts and ends with no stop request pending."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from searchtrack.core.interrupt import clear_stop


@pytest.fixture(autouse=True)
def _clean_stop() -> Iterator[None]:
    clear_stop()
    yield
    clear_stop()
