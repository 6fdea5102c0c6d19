"""lut_baker: the made-up skin model (Baba, Mukaigawa, Yagi), evaluated exactly, fitted and
baked into lookup tables.  Pure numpy/scipy: nothing here knows about Blender."""

__version__ = "0.1.0"
