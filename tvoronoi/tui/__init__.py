"""The terminal UI of tvoronoi; it uses only the public Python API.

- ``app``: the App (``main()``), its side panel, the build and save workers.
- ``canvas``: the widget that draws the diagram and owns the view.
- ``raster``: the numpy braille rasterizer (dots, fills, styled rows).
- ``colours``: palettes and the colouring in which neighbouring cells differ.
- ``screens``: the help screen and the path dialog.
"""
