"""Run: the `make` pipeline, step by step, into one output folder."""
