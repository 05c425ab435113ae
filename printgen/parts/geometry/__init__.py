"""Net and cable geometry: centre-line graphs (numpy only) and solids (the `geometry` extra)."""
