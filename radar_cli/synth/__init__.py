"""Synthetic vases with full ground truth (paper supplementary "Synthetic Vases"): shapes, textures, lighting,
and the generator that renders and writes them."""
