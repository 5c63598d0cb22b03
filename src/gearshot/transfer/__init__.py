"""Transfer functions: estimation from healthy signals, resampling and propagation; FRF
container, UFF58/CSV I/O, hammer-test estimation, modal synthesis, physical-time filtering.
"""

from . import bank, estimation, filtering, function, impacts, modal, uff
from .bank import *  # noqa: F403
from .estimation import *  # noqa: F403
from .filtering import *  # noqa: F403
from .function import *  # noqa: F403
from .impacts import *  # noqa: F403
from .modal import *  # noqa: F403
from .uff import *  # noqa: F403

# The public names, said once: each submodule's own ``__all__``.
__all__ = [*estimation.__all__, *function.__all__, *bank.__all__, *uff.__all__,
           *impacts.__all__, *modal.__all__, *filtering.__all__]
