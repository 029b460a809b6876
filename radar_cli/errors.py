"""The exceptions radar raises on bad input; only the CLI layer turns them into exit codes."""


class RadarError(Exception):
    """Base class: a problem the user can fix, reported as one line."""

    exit_status = 2  # the command's exit status when this error ends it


class ConfigError(RadarError):
    """A configuration file or value is malformed (unknown key, wrong type, out of range)."""


class InputError(RadarError):
    """An input file, folder or tensor is missing or malformed."""


class NothingToDoError(InputError):
    """The inputs hold nothing to work on (an empty folder, a missing path): exit status 1, nothing written."""

    exit_status = 1


class CheckpointError(RadarError):
    """A checkpoint is missing, corrupt, or does not match the configuration."""


class NetworkError(RadarError):
    """A remote service failed in a way that retrying did not fix: exit status 1."""

    exit_status = 1
