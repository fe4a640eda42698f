"""Bodies of fixtures that several test modules share in shape."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import TypeVar

T = TypeVar("T")


@contextlib.contextmanager
def factory(make: Callable[..., T],
            end: Callable[[T], object]) -> Iterator[Callable[..., T]]:
    """The body of a factory fixture: yields a function that calls
    ``make(*args, **kw)`` and keeps what it returns; when the block ends,
    ``end`` is called on each of them, in the order they were made.  In a
    fixture: ``with factory(make, end) as f: yield f``."""
    made: list[T] = []

    def make_one(*args, **kw) -> T:
        made.append(make(*args, **kw))
        return made[-1]
    try:
        yield make_one
    finally:
        for obj in made:
            end(obj)
