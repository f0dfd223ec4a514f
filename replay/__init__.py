"""paper-replay: re-run landmark high-speed robotics experiments from YAML scenarios into MCAP logs."""

__version__ = "0.1.0"
