"""The exceptions radar raises on bad input; only the CLI layer turns them into exit codes."""


class RadarError(Exception):
    """Base class: a problem the user can fix, reported as one line."""


class ConfigError(RadarError):
    """A configuration file or value is malformed (unknown key, wrong type, out of range)."""


class InputError(RadarError):
    """An input file, folder or tensor is missing or malformed."""


class CheckpointError(RadarError):
    """A checkpoint is missing, corrupt, or does not match the configuration."""


class NetworkError(RadarError):
    """A remote service failed in a way that retrying did not fix."""
