"""One object seen in several photographs: one solid fitted to all side views, the turns between views found from
their textures, and the albedo fused over 360 deg (docs/multiview.md)."""
