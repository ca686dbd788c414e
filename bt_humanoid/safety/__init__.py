"""Safety monitors feeding the compiler's Safety guards."""
