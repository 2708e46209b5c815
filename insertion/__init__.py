"""Explicit insertion solver: a scope (rod) pushed through a hyperelastic colon (thin shell)."""
