"""A run's per-step records, kept in a few large arrays so that a long run's memory grows by its data only.

A step's tracks or detections are a frozen dataclass of arrays that share their leading length (the step's
rows); kept as they are, a Python object per array per step costs more than the rows themselves.
:class:`StepHistory` copies each step's rows into chunks of ``CHUNK_ROWS`` rows and gives a step back as
the same dataclass over views of them.
"""

from collections.abc import Iterator, Sequence
from dataclasses import fields, is_dataclass
from typing import Any, Generic, TypeVar, overload

import numpy as np

Record = TypeVar("Record")

CHUNK_ROWS = 4096


class StepHistory(Sequence[Record], Generic[Record]):
    """The records of a run's steps, in order, one per :meth:`append`.

    Every record is a dataclass of the same type whose array fields share their leading length (its
    rows) and whose other fields are numbers (a track list's next id); every array field keeps the
    trailing shape and a dtype its first record's can hold. Reading a step gives the dataclass over
    read-only views of the chunk its rows went into. chunk_rows : the rows of a chunk (a step with more
    has a chunk of its own).
    """

    def __init__(self, chunk_rows: int = CHUNK_ROWS) -> None:
        self._least_chunk_rows = chunk_rows
        self._kind: type | None = None
        self._arrays: dict[str, np.ndarray] = {}
        self._numbers: dict[str, type] = {}
        self._chunks: list[dict[str, np.ndarray]] = []
        self._chunk_rows = 0
        self._filled = 0
        # Per step: chunk, first row, stop row, then each number field's value.
        self._steps = np.zeros((0, 3))
        self._count = 0

    def append(self, record: Record) -> None:
        """Add the next step's ``record``."""
        if not is_dataclass(record):
            raise TypeError(f"a step history keeps dataclasses, not {type(record).__name__}")
        values = {field.name: getattr(record, field.name) for field in fields(record)}
        if self._kind is None:
            self._kind = type(record)
            self._arrays = {name: value for name, value in values.items() if isinstance(value, np.ndarray)}
            self._numbers = {name: type(value) for name, value in values.items() if name not in self._arrays}
            self._steps = np.zeros((64, 3 + len(self._numbers)))
        elif type(record) is not self._kind:
            raise TypeError(f"a history of {self._kind.__name__} given a {type(record).__name__}")
        rows = len(next(iter(values[name] for name in self._arrays))) if self._arrays else 0
        if not self._chunks or self._filled + rows > self._chunk_rows:
            self._start_chunk(max(rows, self._least_chunk_rows))
        chunk = self._chunks[-1]
        for name, example in self._arrays.items():
            value = np.asarray(values[name])
            if value.shape[1:] != example.shape[1:] or not np.can_cast(value.dtype, example.dtype, "same_kind"):
                raise ValueError(
                    f"{self._kind.__name__}.{name} of shape {value.shape} and dtype {value.dtype} in a history of "
                    f"shape (n, {', '.join(map(str, example.shape[1:]))}) and dtype {example.dtype}"
                )
            chunk[name][self._filled : self._filled + rows] = value
        if self._count == len(self._steps):
            self._steps = np.concatenate([self._steps, np.zeros_like(self._steps)])
        numbers = [float(values[name]) for name in self._numbers]
        self._steps[self._count] = [len(self._chunks) - 1, self._filled, self._filled + rows, *numbers]
        self._filled += rows
        self._count += 1

    def _start_chunk(self, rows: int) -> None:
        self._chunks.append(
            {name: np.empty((rows, *example.shape[1:]), example.dtype) for name, example in self._arrays.items()}
        )
        self._chunk_rows, self._filled = rows, 0

    def __len__(self) -> int:
        return self._count

    @overload
    def __getitem__(self, index: int) -> Record: ...

    @overload
    def __getitem__(self, index: slice) -> list[Record]: ...

    def __getitem__(self, index: int | slice) -> Record | list[Record]:
        if isinstance(index, slice):
            return [self[step] for step in range(*index.indices(self._count))]
        step = index + self._count if index < 0 else index
        if not 0 <= step < self._count:
            raise IndexError(f"step {index} of a history of {self._count}")
        chunk, first, stop, *numbers = self._steps[step]
        views: dict[str, Any] = {}
        for name, buffer in self._chunks[int(chunk)].items():
            view = buffer[int(first) : int(stop)]
            view.flags.writeable = False
            views[name] = view
        for (name, kind), value in zip(self._numbers.items(), numbers, strict=True):
            views[name] = kind(value)
        assert self._kind is not None
        return self._kind(**views)

    def __iter__(self) -> Iterator[Record]:
        return (self[step] for step in range(self._count))
