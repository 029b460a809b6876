"""The RADAR networks (shape, lighting, albedo, discriminator), their outputs and their losses."""
