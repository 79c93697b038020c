"""Cell colours: palettes for dark and light themes, and a colouring in which neighbours differ."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

# Every planar graph has a vertex of degree <= 5, so peeling such vertices and
# colouring them back in reverse never meets more than 5 coloured neighbours:
# 6 colours suffice, and a palette of 8 leaves room to spread them.
PLANAR_DEGENERACY = 5
# Fixed seed of the tie-breaking priorities: the same diagram is always coloured the same way.
PRIORITY_SEED = 0x7F4A7C15
# Multiplier that scatters each cell's first-choice colour over the palette (a golden-ratio step).
SCATTER = 0x9E3779B1
# Colour masks are one byte: at most 8 colours.
MAX_COLOURS = 8


# The characters under the keyboard cursor take their cell's colour shifted this many
# tint steps: the other way from a tint (darker on the dark theme, lighter on the light
# one), so that the light marks of the dark theme (and the dark ones of the light) keep
# their contrast there.
HIGHLIGHT_STEPS = -1

# The six levels of each channel of the xterm 256-colour cube.
CUBE_LEVELS = (0x00, 0x5F, 0x87, 0xAF, 0xD7, 0xFF)


def cube_shift(colour: str, steps: int) -> str:
    """A cube colour moved ``steps`` levels up (lighter) or down on every channel, within the cube."""
    channels = [int(colour[k : k + 2], 16) for k in (1, 3, 5)]
    levels = [min(range(6), key=lambda i: abs(CUBE_LEVELS[i] - c)) for c in channels]
    return "#" + "".join(f"{CUBE_LEVELS[min(max(lv + steps, 0), 5)]:02x}" for lv in levels)


@dataclass(frozen=True)
class Palette:
    """The colours of one theme: muted cell fills and the marks drawn over them.

    The playback and editing colours: ``future`` for sites the algorithm has
    not reached, ``sweep``, ``beach``, ``circle`` and ``growing`` for Fortune's
    sweep line, beach line, pending circle events and growing edges,
    ``event`` for what the current step did (and the site being moved),
    ``conflict`` and ``conflict_fill`` for the triangles an insertion
    destroyed, ``walk`` for those its point location visited, ``cursor``
    for the keyboard cursor's cross. ``tints`` are the fills of the cells an insertion took area from, ``highlights`` those of
    the characters under the keyboard cursor (the cell's own colour, darker
    on a dark theme and lighter on a light one, so that the site and edges
    under the cursor keep showing).
    """

    fills: tuple[str, ...]
    edge: str
    site: str
    vertex: str
    delaunay: str
    tint_steps: int
    future: str
    sweep: str
    beach: str
    circle: str
    growing: str
    event: str
    conflict: str
    conflict_fill: str
    cursor: str
    walk: str
    # False: no cell fills (a terminal without colours, or with only 16)
    filled: bool = True
    # the background of the characters under the keyboard cursor when cells are not filled
    plain_highlight: str = "#808080"

    @property
    def tints(self) -> tuple[str, ...]:
        return tuple(cube_shift(c, self.tint_steps) for c in self.fills)

    @property
    def highlights(self) -> tuple[str, ...]:
        return tuple(cube_shift(c, HIGHLIGHT_STEPS * self.tint_steps) for c in self.fills)

    @property
    def backgrounds(self) -> tuple[str | None, ...]:
        """Every background a character can have, indexed by its fill + 1 (no fill first)."""
        if not self.filled:
            n = len(self.fills)
            return (None, *(None,) * (2 * n), self.conflict_fill, *(self.plain_highlight,) * n)
        return (None, *self.fills, *self.tints, self.conflict_fill, *self.highlights)


# All colours are exact entries of the xterm 256-colour cube, so a terminal (or a
# tmux over SSH) that has only 256 colours shows the same 8 distinct fills.

# Muted mid-dark fills: light edges and bright marks stay readable on each of them.
DARK = Palette(
    fills=(
        "#5f5f87",  # slate
        "#5f875f",  # sage
        "#875f5f",  # rosewood
        "#5f8787",  # grey teal
        "#87875f",  # olive
        "#875f87",  # mauve
        "#005f87",  # deep sky
        "#875f00",  # umber
    ),
    edge="#eeeeee",
    site="#ffd75f",
    vertex="#ff8787",
    delaunay="#87d7d7",
    tint_steps=1,
    future="#808080",
    sweep="#5fd7ff",
    beach="#ffaf00",
    circle="#d787ff",
    growing="#87ff87",
    event="#ff5fff",
    conflict="#ff5f5f",
    conflict_fill="#870000",
    cursor="#ff87ff",
    walk="#5fafff",
)

# Pastel fills: dark edges and deep marks stay readable on each of them.
LIGHT = Palette(
    fills=(
        "#afafd7",  # lavender
        "#afd7af",  # pale green
        "#d7afaf",  # pale rose
        "#afd7d7",  # pale cyan
        "#d7d7af",  # khaki
        "#d7afd7",  # orchid
        "#87afd7",  # steel blue
        "#d7af87",  # tan
    ),
    edge="#1c1c1c",
    site="#af0000",
    vertex="#5f00af",
    delaunay="#005f5f",
    tint_steps=-1,
    future="#8a8a8a",
    sweep="#0087af",
    beach="#d75f00",
    circle="#8700d7",
    growing="#008700",
    event="#d700d7",
    conflict="#d70000",
    conflict_fill="#ffafaf",
    cursor="#870087",
    walk="#005fd7",
)


# Without colours (NO_COLOR: Textual turns colours into greys) or with only 16 (each
# colour becomes the nearest of the 16), eight muted fills collapse into a few and the
# marks drawn over them get lost. These palettes draw no fills: grey edges, and sites
# in the brightest (darkest) colour there is, which stays the brightest (darkest) grey.
PLAIN_DARK = replace(
    DARK,
    filled=False,
    edge="#808080",
    site="#ffff00",
    vertex="#ff0000",
    delaunay="#008080",
    cursor="#ff00ff",
    walk="#00ffff",
    plain_highlight="#000080",
)
PLAIN_LIGHT = replace(
    LIGHT,
    filled=False,
    edge="#808080",
    site="#000000",
    vertex="#800000",
    delaunay="#008080",
    cursor="#800080",
    walk="#000080",
    plain_highlight="#c0c0c0",
)


def palette_for(dark: bool, plain: bool = False) -> Palette:
    """The palette that reads on a dark (True) or light (False) theme; ``plain``: without fills."""
    if plain:
        return PLAIN_DARK if dark else PLAIN_LIGHT
    return DARK if dark else LIGHT


def cell_adjacency(diagram) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of neighbouring cells of a diagram, each pair once.

    Cells f and g are neighbours when a Voronoi edge separates them: some
    half-edge e has ``he_face[e] == f`` and ``he_face[he_twin[e]] == g``.
    Each edge is taken once, from the half-edge of the two with the lower
    index; two cells share at most one edge (cells are convex, and their
    common boundary lies on one bisector), so no pair repeats and no sort is
    needed.

    Returns
    -------
    (a, b) : two (k,) integer arrays (the half-edges' type) with ``a < b``, in half-edge order.
    """
    faces = np.asarray(diagram.he_face)
    twins = np.asarray(diagram.he_twin)
    keep = twins > np.arange(twins.size, dtype=twins.dtype)
    keep &= faces >= 0
    a = faces[keep]
    b = faces[twins[keep]]
    keep = (b >= 0) & (a != b)
    a, b = a[keep], b[keep]
    return np.minimum(a, b), np.maximum(a, b)


def colour_graph(n: int, a: np.ndarray, b: np.ndarray, n_colours: int = MAX_COLOURS) -> np.ndarray:
    """Colour the vertices of a planar graph so that no edge joins two equal colours.

    Vectorised greedy colouring in a degeneracy order: peel every vertex of
    degree <= 5 in rounds, then colour the rounds back from the last one. In a
    round, the vertices whose uncoloured round-neighbours all have a lower
    (random, seeded) priority are coloured together. Each vertex then sees at
    most 5 coloured neighbours and takes a free colour, trying first a colour
    scattered by its number so that the whole palette gets used.

    Parameters
    ----------
    n : int
        Number of vertices.
    a, b : (k,) int arrays
        The edges, each given once (either direction).
    n_colours : int
        Size of the palette, 6 to 8 for the guarantee.

    Returns
    -------
    (n,) int8 colours in ``0 .. n_colours - 1``. No edge joins equal colours
    in a planar graph; a graph that is not planar may have clashes.

    >>> a, b = [0, 1, 2, 3, 0], [1, 2, 3, 0, 2]  # a square and one diagonal
    >>> c = colour_graph(4, a, b)
    >>> bool((c[a] != c[b]).all())
    True
    """
    if not 1 <= n_colours <= MAX_COLOURS:
        raise ValueError(f"n_colours must be 1 to {MAX_COLOURS}, got {n_colours}")
    index = np.int32 if n < np.iinfo(np.int32).max else np.int64
    a = np.asarray(a).astype(index, copy=False)
    b = np.asarray(b).astype(index, copy=False)
    # peel the vertices of low degree, a whole round at once
    round_of = np.full(n, -1, np.int32)
    alive = np.ones(n, bool)
    deg = np.bincount(a, minlength=n) + np.bincount(b, minlength=n)
    live_a, live_b = a, b
    n_rounds = 0
    while alive.any():
        peel = alive & (deg <= PLANAR_DEGENERACY)
        if not peel.any():
            # not planar (a Voronoi diagram never gets here): peel the least connected
            peel = alive & (deg == deg[alive].min())
        round_of[peel] = n_rounds
        alive &= ~peel
        keep_a, keep_b = alive[live_a], alive[live_b]
        # an edge that lost one end lowers the degree of the other
        deg -= np.bincount(live_b[keep_b & ~keep_a], minlength=n)
        deg -= np.bincount(live_a[keep_a & ~keep_b], minlength=n)
        keep = keep_a & keep_b
        live_a, live_b = live_a[keep], live_b[keep]
        n_rounds += 1

    priority = np.random.default_rng(PRIORITY_SEED).permutation(n).astype(index)
    first_choice = (np.arange(n, dtype=np.uint64) * np.uint64(SCATTER) >> np.uint64(16)) % np.uint64(n_colours)
    first_choice = first_choice.astype(np.int64)
    full = (1 << n_colours) - 1
    colour = np.full(n, -1, np.int8)
    taken = np.zeros(n, np.uint8)  # bit c set: a coloured neighbour has colour c
    # an edge between rounds matters only to its end peeled first (coloured later);
    # an edge inside a round only to its end of lower priority, which waits for the other
    ra, rb = round_of[a], round_of[b]
    cross = ra != rb
    owner = np.where(ra < rb, a, b)[cross]
    other = np.where(ra < rb, b, a)[cross]
    owner_round = np.minimum(ra, rb)[cross]
    inner = ~cross
    ia, ib = a[inner], b[inner]
    up = priority[ib] > priority[ia]
    all_wait_s, all_wait_d = np.where(up, ia, ib), np.where(up, ib, ia)
    wait_round = round_of[all_wait_s]

    # colour the rounds back, the last peeled first
    for k in range(n_rounds - 1, -1, -1):
        members = np.flatnonzero(round_of == k)
        # neighbours in later rounds are coloured for good: note their colours once
        mine = owner_round == k
        _add_colours(taken, owner[mine], colour[other[mine]], n_colours)
        # neighbours in this round: wait_s waits for wait_d while wait_d is uncoloured
        mine = wait_round == k
        wait_s, wait_d = all_wait_s[mine], all_wait_d[mine]
        while members.size:
            blocked = np.zeros(n, bool)
            blocked[wait_s] = True
            ready = members[~blocked[members]]
            # the free colour nearest after the scattered first choice
            used = taken[ready].astype(np.int64) & full
            off = first_choice[ready]
            rotated = ((used >> off) | (used << (n_colours - off))) & full
            free = ~rotated & (rotated + 1)
            pick = (_lowest_bit(free) + off) % n_colours
            # every colour taken (not planar): keep the first choice and accept the clash
            crowded = rotated == full
            pick[crowded] = off[crowded]
            colour[ready] = pick
            # tell those that waited for them what was just taken; they wait no more
            just = np.zeros(n, bool)
            just[ready] = True
            members = members[~just[members]]
            told = just[wait_d]
            _add_colours(taken, wait_s[told], colour[wait_d[told]], n_colours)
            wait_s, wait_d = wait_s[~told], wait_d[~told]
    return colour


def _add_colours(taken: np.ndarray, owners: np.ndarray, colours: np.ndarray, n_colours: int) -> None:
    """Set bit ``colours[j]`` of ``taken[owners[j]]`` for every j (owners may repeat)."""
    np.bitwise_or.at(taken, owners, np.left_shift(np.uint8(1), colours.astype(np.uint8)))


def _lowest_bit(x: np.ndarray) -> np.ndarray:
    """Index of the single set bit of each power of two in x."""
    return np.log2(x.astype(np.float64)).astype(np.int64)


def cell_colours(diagram, n_colours: int = MAX_COLOURS) -> np.ndarray:
    """A palette index for every cell of a diagram, different across every Voronoi edge.

    Returns
    -------
    (n,) int8 in ``0 .. n_colours - 1``; a repeated point takes the colour of
    its first copy.
    """
    n = int(diagram.n_sites)
    a, b = cell_adjacency(diagram)
    colour = colour_graph(n, a, b, n_colours)
    return colour[np.asarray(diagram.site_of, np.int64)]


def repair_colours(colours: np.ndarray, neighbours, todo, n_colours: int = MAX_COLOURS) -> np.ndarray:
    """Give new colours to a few cells so that they differ from their neighbours; the others keep theirs.

    Parameters
    ----------
    colours : (n,) int8, changed in place
        Current colours, -1 for a cell without one.
    neighbours : callable
        ``neighbours(i)`` gives the cells next to cell i (an int array).
    todo : iterable of int
        The cells to check: each keeps its colour unless a neighbour has it
        or it has none.

    Returns
    -------
    ``colours``. A cell with neighbours of every colour keeps the colour
    fewest of them share.
    """
    for i in todo:
        i = int(i)
        around = np.asarray(neighbours(i), np.int64)
        near = colours[around]
        near = near[near >= 0]
        mine = int(colours[i])
        if mine >= 0 and not (near == mine).any():
            continue
        used = 0
        for c in near.tolist():
            used |= 1 << c
        # the free colour nearest after the cell's scattered first choice (as colour_graph)
        first = int((i * SCATTER >> 16) % n_colours)
        pick = -1
        for k in range(n_colours):
            c = (first + k) % n_colours
            if not used >> c & 1:
                pick = c
                break
        if pick < 0:  # every colour taken around it (not planar, or a crowded vertex)
            pick = int(np.argmin(np.bincount(near, minlength=n_colours)))
        colours[i] = pick
    return colours


def adjacency_lists(n: int, a: np.ndarray, b: np.ndarray):
    """A ``neighbours(i)`` function over the undirected pairs (a, b), in CSR form."""
    a = np.asarray(a, np.int64)
    b = np.asarray(b, np.int64)
    src = np.concatenate([a, b])
    dst = np.concatenate([b, a])
    order = np.argsort(src, kind="stable")
    dst = dst[order]
    offsets = np.zeros(n + 1, np.int64)
    np.cumsum(np.bincount(src, minlength=n), out=offsets[1:])
    return lambda i: dst[offsets[i] : offsets[i + 1]]
