"""The engine: a robot stack, a mission run on it (compiler, safety and recovery decorators, executor, verdict),
and the event log."""
