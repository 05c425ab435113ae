"""Parts: meshes (geometry), STL/3MF/STEP export, direct G-code and slicer settings."""
