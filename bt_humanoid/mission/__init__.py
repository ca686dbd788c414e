"""The mission language: schema, YAML loader with source positions, compiler."""
