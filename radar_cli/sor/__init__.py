"""Solids of revolution: profiles, poses, the fixed camera, surface grids and mesh export (pure tensor functions)."""
