"""The command line, ``python -m lut_baker <command>``: one module per command."""
