"""Validation of the runtime against the exact model: reference sphere images, image
comparison, the stock-Principled baseline and the stability sweep."""
