"""Colon models, scopes and manoeuvres: what is inserted, into what, and how (docs/model.md).
"""
