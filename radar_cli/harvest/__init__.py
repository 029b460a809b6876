"""Harvesting a museum collection: Met API client, SQLite catalog, validated image downloads."""
