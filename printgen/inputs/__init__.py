"""Inputs: the prototype file, its schema, and the profiles (materials, printers, print styles)."""
