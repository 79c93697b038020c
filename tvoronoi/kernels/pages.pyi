"""Type stub of pages.pyx: the allocator of a build's arrays (large ones mapped on their own)."""

from contextlib import AbstractContextManager
from typing import Any

HANDLER: Any
MAPS: bool

def mapped() -> AbstractContextManager[None]: ...
def trim_heap() -> bool: ...
def populate_pages(a: Any) -> None: ...
