"""Cycles' closures in numpy and the fits of the two shader tiers to baked tables."""
