"""Meshes for fabric specimens: strips, rectangles, Cusick annuli and imported meshes."""
