"""Studies of many insertions: sweeps, their specs and workers, the claims, the source's reference numbers
and the verification problems.
"""
