# Type information of the compiled core (halsdk/core/_core.pyx): the
# extension is typed as a module of Any values; the public layer above it
# (halsdk.hal, halsdk.component, halsdk.types) gives the typed API.
from typing import Any

def __getattr__(name: str) -> Any: ...
