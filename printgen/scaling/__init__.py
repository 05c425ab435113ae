"""Design: similitude targets, section and material selection, the printable Design record."""
