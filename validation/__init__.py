"""The builder of the validation report (docs/validation/report.md) and the tools around it.

A tool folder of the repository, like ``benchmarks/``, not part of the installed ``colonsim``
package: it reads sweep folders and the committed sweep records (``benchmarks/records/``) and
writes the report's page, JSON and figures into ``docs/validation/``, so it needs a checkout. Run
its entry points from the repository root::

    python -m validation.report --help               # the report (docs/how-to/validation_report.md)
    python -m validation.quasi_static_checks --help  # the quasi-static checks on sweeps or records
    python -m validation.ringing_half_speed --help   # the half-speed sweep of the runs that ring
    python -m validation.sweep_records --help        # pack / unpack / list the sweep records

Imports flow one way: ``validation`` imports ``colonsim``, a benchmark may import ``validation``,
and ``colonsim`` imports neither (tests/test_architecture.py).
"""
