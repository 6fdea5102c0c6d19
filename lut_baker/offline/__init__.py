"""What never runs inside Blender and is not shipped in the extension: validation against
reference images, the paper's measurement protocols and fits, its figures, the table files
(OpenEXR) and the command line.  These modules may use scipy, matplotlib and OpenImageIO;
nothing outside this package imports them."""
