"""The mechanics: bodies (rod, shell), wall material, contact, constraints and the explicit integrator.

No colon, scope or study knowledge lives here (docs/architecture.md).
"""
