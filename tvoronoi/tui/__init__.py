"""The terminal UI of tvoronoi; it uses only the public Python API.

- ``app``: the App (``main()``): layout, side panel, status line, help; put together from
  - ``building``: whole diagrams, built now or in a worker thread;
  - ``files``: opening point files, saving cells (in a worker thread);
  - ``playback``: the engines step by step, with ``timeline`` (the scrubbing bar);
  - ``editing``: adding, moving and deleting sites through dynamic updates;
  - ``inspector``: the cell under the keyboard cursor or the mouse pointer, described.
- ``canvas``: the widget that draws the diagram, owns the view, reports clicks and drags.
- ``raster``: the numpy rasterizer (views, scenes, layers, fills, styled rows, redrawing a part).
- ``dots``: braille dots: segments and points on a dot array, packed into characters.
- ``overlay``: pictures of algorithm steps (beach line, circle events, conflict regions).
- ``live``: an edited diagram kept drawable cell by cell.
- ``colours``: palettes and the colouring in which neighbouring cells differ.
- ``screens``: the help screen and the path dialog.
"""
