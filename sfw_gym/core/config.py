"""One way to declare and check configuration: frozen dataclasses whose fields carry their range.

Every subsystem's settings (radio, robot, mapper, floorplan generator, reward, env) are a frozen
dataclass deriving from :class:`Config`; each field declares what it accepts with
:func:`setting`, and :meth:`Config.__post_init__` checks every field in one place, normalising
numbers (an ``int`` given for a float field becomes a ``float``). Dicts of overrides go through
:meth:`Config.from_dict`, which names the nearest valid key for an unknown one::

    @dataclass(frozen=True)
    class RewardConfig(Config):
        reward_scale: float = setting(0.01, ge=0.0, le=1e6)
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Iterable, Mapping
from dataclasses import MISSING, Field, asdict, dataclass, field, fields
from typing import Any, ClassVar, TypeVar

from sfw_gym.core.errors import ConfigError

C = TypeVar("C", bound="Config")


@dataclass(frozen=True)
class Range:
    """What one field accepts (see :func:`setting`)."""

    ge: float | None = None
    gt: float | None = None
    le: float | None = None
    lt: float | None = None
    integer: bool = False
    optional: bool = False
    choices: tuple[Any, ...] | None = None

    def describe(self) -> str:
        """``"an int in [1, 32]"``, ``"a number > 0"``, ``"one of ('a', 'b')"`` ..."""
        if self.choices is not None:
            text = f"one of {self.choices}"
        else:
            kind = "an int" if self.integer else "a finite number"
            lo = f"[{_fmt(self.ge)}" if self.ge is not None else None
            lo = f"({_fmt(self.gt)}" if self.gt is not None else lo
            hi = f"{_fmt(self.le)}]" if self.le is not None else None
            hi = f"{_fmt(self.lt)})" if self.lt is not None else hi
            if lo and hi:
                text = f"{kind} in {lo}, {hi}"
            elif lo:
                text = f"{kind} {'>=' if lo[0] == '[' else '>'} {lo[1:]}"
            elif hi:
                text = f"{kind} {'<=' if hi[-1] == ']' else '<'} {hi[:-1]}"
            else:
                text = kind
        return f"None or {text}" if self.optional else text

    def check(self, where: str, value: Any) -> Any:
        """``value`` normalised (int or float), or a ConfigError naming ``where``."""
        if value is None and self.optional:
            return None
        if self.choices is not None:  # by type too: 1 is not True, 1.0 is not "1"
            if any(type(value) is type(c) and value == c for c in self.choices):
                return value
            raise ConfigError(f"{where} must be {self.describe()}, got {value!r}")
        ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
        if ok and self.integer:
            ok = isinstance(value, numbers.Integral)
        if ok:
            v = int(value) if self.integer else float(value)
            ok = math.isfinite(v) and (
                (self.ge is None or v >= self.ge)
                and (self.gt is None or v > self.gt)
                and (self.le is None or v <= self.le)
                and (self.lt is None or v < self.lt)
            )
        if not ok:
            raise ConfigError(f"{where} must be {self.describe()}, got {value!r}")
        return v


def _fmt(v: float) -> str:
    return f"{int(v):,}" if float(v).is_integer() else f"{v:g}"


def setting(
    default: Any = MISSING,
    *,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    integer: bool = False,
    optional: bool = False,
    choices: Iterable[Any] | None = None,
    default_factory: Any = MISSING,
) -> Any:
    """A dataclass field with its valid range (``ge``/``gt``/``le``/``lt`` bounds, ``integer``,
    ``optional`` for None, or a set of ``choices``), checked by :class:`Config`."""
    rng = Range(ge, gt, le, lt, integer, optional, None if choices is None else tuple(choices))
    if default_factory is not MISSING:
        return field(default_factory=default_factory, metadata={"range": rng})
    return field(default=default, metadata={"range": rng})


def setting_of(cls: type, name: str) -> Any:
    """Field ``name`` of the config class ``cls`` (its default and range) for another config
    class that shares the setting: one place for its default and range."""
    f = {f.name: f for f in fields(cls)}[name]
    return field(default=f.default, metadata=f.metadata)


def check(name: str, value: Any, **bounds: Any) -> Any:
    """``value`` checked against a range given as :func:`setting`'s keywords (for arguments that
    are not dataclass fields, such as an agent's constructor parameters); normalised."""
    if "choices" in bounds:
        bounds["choices"] = tuple(bounds["choices"])
    return Range(**bounds).check(name, value)


def brief_repr(value: Any) -> str:
    """``repr(value)`` on one line, at most 80 characters (for error messages)."""
    return " ".join(repr(value).split())[:80]


def float_array(name: str, value: Any) -> Any:
    """``value`` as a float64 numpy array, or a ConfigError naming ``name`` (for values that
    are no numbers at all: strings, dicts, ragged lists)."""
    import numpy as np

    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ConfigError(f"{name} must be numbers, got {brief_repr(value)}") from None


def unknown_key_error(what: str, key: Any, valid: Iterable[str]) -> ConfigError:
    """``ConfigError`` for an unknown key, naming the nearest valid one."""
    valid = sorted(valid)
    near = difflib.get_close_matches(str(key), valid, n=1)
    hint = f"did you mean {near[0]!r}? " if near else ""
    return ConfigError(f"{what}: unknown key {key!r}; {hint}valid keys: {valid}")


class Config:
    """Base of the frozen configuration dataclasses: validation, ``from_dict`` and ``to_dict``."""

    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]
    #: How messages name a field: ``"<prefix>.<field>"`` (default the class name); ``""`` for
    #: settings that users pass as plain keyword arguments (``gym.make(..., max_steps=...)``).
    prefix: ClassVar[str | None] = None

    def __post_init__(self) -> None:
        prefix = type(self).__name__ if self.prefix is None else self.prefix
        for f in fields(self):
            rng = f.metadata.get("range")
            if rng is not None:
                where = f"{prefix}.{f.name}" if prefix else f.name
                value = rng.check(where, getattr(self, f.name))
                object.__setattr__(self, f.name, value)
        self.validate()

    def validate(self) -> None:
        """Rules across fields (subclasses override); raise ConfigError."""

    @classmethod
    def from_dict(cls: type[C], values: Mapping[str, Any] | None, what: str | None = None) -> C:
        """Build from a dict of overrides; an unknown key is named with the nearest valid one."""
        what = what or cls.__name__
        if values is None:
            values = {}
        if not isinstance(values, Mapping):
            raise ConfigError(f"{what} must be a dict of overrides, got {type(values).__name__}")
        names = cls.__dataclass_fields__.keys()
        for key in values:
            if key not in names:
                raise unknown_key_error(what, key, names)
        return cls(**values)

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable dict of the fields (tuples as lists)."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}
