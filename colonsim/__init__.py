"""colonsim: how much a colonoscope deforms the colon.

The command line lives in :mod:`colonsim.cli`; the workflows are the packages
:mod:`identification` (tissue calibration) and :mod:`insertion` (explicit insertion solver).
"""

from colonsim.errors import ColonsimError

__all__ = ["ColonsimError"]
__version__ = "0.1.0"
