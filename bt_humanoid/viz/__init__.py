"""Watching runs: the live terminal tree, plain status lines, video recording."""
