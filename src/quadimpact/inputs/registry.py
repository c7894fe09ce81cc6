"""The registries of named plug-ins (controllers, estimators): one set of rules for both.

A controller or an estimator is selected by name in scenario files, sweeps and
on the command line. :class:`Registry` holds the entries of one kind and
applies the same rules to both: a name of letters, digits, ``-`` and ``_``; no
silent replacement; a plug-in's step compiled with ``numba.njit`` (the loop
that calls it is compiled, so a plain Python function would fail only once a
run starts); built-ins that cannot be removed; an unknown name as a one-line
input error that lists the known ones and a near miss; the parameters
validated against the entry's model, errors named by their scenario-file key.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any, Generic, Protocol, TypeVar

from pydantic import BaseModel, ValidationError

from quadimpact.errors import InputError, input_error_from_validation, near_miss

__all__ = ["Registry", "is_compiled"]


class _Entry(Protocol):
    name: str
    params: type[BaseModel]

    def __init__(self, **fields: Any) -> None: ...


E = TypeVar("E", bound=_Entry)


def is_compiled(step: Any) -> bool:
    """Whether ``step`` is a Numba dispatcher (``njit``), which a compiled loop can call."""
    try:
        from numba.core.dispatcher import Dispatcher
    except ImportError:  # pragma: no cover (numba is a dependency)
        return callable(step)
    return isinstance(step, Dispatcher)


class Registry(Generic[E]):
    """Entries of one kind of plug-in, by name, in the order they were registered.

    Parameters
    ----------
    what : str
        The kind, as messages and scenario files name it (``"controller"``).
    builtins : iterable of str
        The names that cannot be removed.
    entry_type : type
        The entries' class (fields ``name``, ``kind``, ``params``, ``pack``,
        ``step``, ``description``).
    user_kind : int
        The ``kind`` of a plug-in (its compiled step is called by the loop).
    no_params : type of pydantic.BaseModel
        The parameters of an entry registered without any.
    empty_pack : callable or None
        The packing of a plug-in registered without one (``None``: the packing
        layer's default). A built-in (registered with its ``kind``) keeps
        ``pack=None``: its packer lives in ``quadimpact.packing``, which the
        input layer does not import.
    """

    def __init__(
        self,
        what: str,
        builtins: Iterable[str],
        *,
        entry_type: type[E],
        user_kind: int,
        no_params: type[BaseModel],
        empty_pack: Callable[..., Any] | None,
    ) -> None:
        self.what = what
        self.builtins = tuple(builtins)
        self.entry_type = entry_type
        self.user_kind = int(user_kind)
        self.no_params = no_params
        self.empty_pack = empty_pack
        self._entries: dict[str, E] = {}

    def register(
        self,
        name: str,
        step: Callable | None,
        *,
        params: type[BaseModel] | None,
        pack: Callable[..., Any] | None,
        kind: int | None,
        description: str,
        replace: bool,
    ) -> E:
        """Check and register one entry (the rules of the module docstring); the entry."""
        self._check_new(name, step, kind, replace)
        entry = self.entry_type(
            name=name,
            kind=self.user_kind if kind is None else int(kind),
            params=params or self.no_params,
            pack=pack if pack is not None or kind is not None else self.empty_pack,
            step=step,
            description=description,
        )
        self._entries[name] = entry
        return entry

    def _check_new(self, name: str, step: Callable | None, kind: int | None, replace: bool) -> None:
        """Refuse a registration that breaks the rules (``ValueError``, ``TypeError``)."""
        what = self.what
        if not name or not all(c.isalnum() or c in "-_" for c in name):
            raise ValueError(f"{what} name {name!r}: letters, digits, '-' and '_' only")
        if name in self._entries and not replace:
            raise ValueError(f"{what} {name!r} is already registered (replace=True to replace)")
        if step is None and kind is None:
            raise ValueError(f"{what} {name!r}: give its compiled step (or a built-in kind)")
        if step is not None and not is_compiled(step):
            raise TypeError(
                f"{what} {name!r}: step must be compiled with numba.njit (got "
                f"{type(step).__name__} {getattr(step, '__name__', step)!r}): the loop that "
                "calls it is compiled, and a plain Python function would fail only when a run "
                "starts"
            )

    def remove(self, name: str) -> None:
        """Remove a registered entry (built-ins cannot be removed; an unknown name: nothing)."""
        if name in self.builtins:
            raise ValueError(f"{self.what} {name!r} is built in")
        self._entries.pop(name, None)

    def names(self) -> tuple[str, ...]:
        """Every registered name, built-ins first."""
        return tuple(self._entries)

    def entry(self, name: str) -> E:
        """The entry of ``name``.

        Raises
        ------
        InputError
            Unknown name (with the registered names and a near miss).
        """
        try:
            return self._entries[name]
        except (KeyError, TypeError):
            known = ", ".join(repr(n) for n in self._entries)
            close = near_miss(str(name), list(self._entries))
            hint = f"; did you mean {close!r}?" if close else ""
            raise InputError(f"{self.what}: must be one of {known} (got {name!r}){hint}") from None

    def params(self, name: str, values: Mapping[str, Any] | BaseModel | None) -> BaseModel:
        """The validated parameters of ``name`` (defaults for what is not given).

        Errors name the field by its scenario-file key (``<what>_params.<field>``).
        """
        entry = self.entry(name)
        if isinstance(values, entry.params):
            return values
        try:
            return entry.params.model_validate(dict(values or {}))
        except ValidationError as exc:
            raise input_error_from_validation(
                exc, prefix=(f"{self.what}_params",), model=entry.params
            ) from None
