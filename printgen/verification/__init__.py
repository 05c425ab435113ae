"""Check: solver scenes of prototype and model, load sweeps, and their comparison."""
