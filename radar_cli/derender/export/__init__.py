"""Writing one object's result folder: mesh, texture and environment maps, renders, relit views, its status."""
