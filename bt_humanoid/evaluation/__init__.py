"""bt-eval: benchmark suites over randomized scenes, with injected faults."""
