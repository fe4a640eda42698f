"""Instance naming for components loaded with ``count=N`` or ``names=...``.

A helper of the shipped components (not a component itself).  It turns the
two load parameters into the list of instance names, the way components
made by the reference's halcompile do:

* ``count`` and ``names`` are exclusive; ``count=0`` or an empty ``names``
  counts as not given, and when neither is given the component makes
  ``default_count`` instances;
* with ``count=N`` the instances are ``<comp>.0`` ... ``<comp>.N-1`` (a
  negative count makes none, as in the reference);
* with ``names=a,b`` the instances are ``a`` and ``b``, in that order.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Optional, Union

from halsdk import NAME_LEN, check_name
from halsdk.errors import HalError, InvalidError, error_for_errno

# The modparams entries a count/names component declares.
COUNT_NAMES_MODPARAMS = {
    "count": (int, 0, "number of instances (0: the default)"),
    "names": ([str], "", "instance names, separated by commas"),
}


def split_names(names: Union[str, Sequence[str], None]) -> list[str]:
    """The names given on the load line, as a list; ``[]`` if none."""
    if names is None:
        return []
    if isinstance(names, str):
        parts = names.split(",")
    else:
        parts = [str(n) for n in names]
    if parts == [""]:
        return []
    return parts


def instance_names(comp: str, count: int = 0,
                   names: Union[str, Sequence[str], None] = None,
                   default_count: int = 1,
                   max_count: Optional[int] = None) -> list[str]:
    """Names of the instances to make for ``count``/``names``.

    Raises :class:`halsdk.InvalidError` if both are given, if a name is
    empty, too long or not a valid HAL name, or if ``count`` exceeds
    ``max_count`` (``None``: no limit, as in the reference).
    """
    given = split_names(names)
    if count and given:
        raise InvalidError("count= and names= are mutually exclusive")
    if given:
        for index, name in enumerate(given):
            if not name:
                raise InvalidError(f"names[{index}] is invalid (empty "
                                   "string)")
            if len(name) > NAME_LEN:
                raise InvalidError(
                    f'names: "{name[:NAME_LEN]}" too long')
            check_name(name, "instance")
        return given
    if count == 0:
        count = default_count
    if max_count is not None and count > max_count:
        raise InvalidError(f"count={count} is more than the {max_count} "
                           f"instances {comp} can make")
    return [f"{comp}.{i}" for i in range(count)]


def hal_error(code: int, message: str) -> HalError:
    """The exception for a failed HAL API call that returned ``code`` (a
    negative errno); ``message`` is the core's last error message."""
    return error_for_errno(code, message)
