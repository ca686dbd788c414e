"""Executor, safety/recovery decorators and the event log."""
