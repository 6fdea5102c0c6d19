"""Lookup tables: the baked table set with its grids and lookups, and the one binary codec
(layout and content hash) shared by files and the add-on."""
