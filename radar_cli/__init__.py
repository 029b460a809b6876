"""radar: de-render photographs of solids of revolution into shape, pose, albedo, lighting and material."""

__version__ = "0.1.0"
