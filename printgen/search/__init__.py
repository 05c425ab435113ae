"""The design search: screens thousands of printable nets against the similitude targets, keeps
the Pareto front, and verifies the best with the solver (locally or on a Dask cluster)."""
