"""One insertion: build it from an InsertionCase, run it, record it, judge its outcome, write its files.
"""
