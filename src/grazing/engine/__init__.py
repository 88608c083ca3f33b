"""The integration engine: Taylor kernels, event location, resets, chattering.

The public entry point is :func:`grazing.simulate` (``grazing.engine.simulate``).
"""
