"""bt-humanoid: behaviour-tree missions for a simulated humanoid in MuJoCo."""

__version__ = "0.1.0"
