"""Figures (matplotlib): the paper's figures, diagnostics and transfer-function plots.

Every function takes ``ax=None`` / ``axes=None`` (a new figure is made when omitted) and
returns what it drew. Nothing here selects a matplotlib backend: that is the
application's choice (the ``gearshot`` command line uses the non-interactive Agg).
"""

from __future__ import annotations

from . import fault_types, paper, transfer
from .fault_types import *  # noqa: F403
from .paper import *  # noqa: F403
from .transfer import *  # noqa: F403

# The public names, said once: each submodule's own ``__all__``.
__all__ = [*paper.__all__, *transfer.__all__, *fault_types.__all__]
