"""colonsim: how much a colonoscope deforms the colon.

The workflows as functions: :func:`calibrate`, :func:`insert`, :func:`sweep`,
:func:`fit_surrogate`, :func:`predict`, :func:`recommend` (defined in :mod:`colonsim.api`), and
:func:`calibrate_strip`, :func:`calibrate_multimode`, :func:`export_cards`
(:mod:`colonsim.api_calibration`) and :func:`simulate` (:mod:`colonsim.api_insertion`). The
command line lives in :mod:`colonsim.cli`; the physics in the subpackages
:mod:`colonsim.identification` (tissue calibration), :mod:`colonsim.insertion` (explicit
insertion solver) and :mod:`colonsim.surrogate` (Gaussian-process surrogate).
"""

from colonsim.errors import ColonsimError

__version__ = "0.1.0"

# The public API is re-exported lazily (PEP 562): ``import colonsim`` stays cheap and loads no
# module of a higher layer; the first use of ``colonsim.insert`` imports colonsim.api
# (docs/architecture.md, "Layers").
_API = ("calibrate", "insert", "sweep", "fit_surrogate", "predict", "recommend", "load_surrogate")
# beside them, in modules of their own (colonsim.api_calibration, colonsim.api_insertion)
_API_CALIBRATION = ("calibrate_strip", "calibrate_multimode", "export_cards")
_API_INSERTION = ("simulate",)
_API_MORE = _API_CALIBRATION + _API_INSERTION
__all__ = ["ColonsimError", *_API, *_API_MORE]


def __getattr__(name):
    if name in _API:
        from colonsim import api

        return getattr(api, name)
    if name in _API_MORE:
        from colonsim import api_calibration, api_insertion

        return getattr(api_calibration if name in _API_CALIBRATION else api_insertion, name)
    raise AttributeError(f"module 'colonsim' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_API) | set(_API_MORE))
