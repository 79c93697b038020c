# Fortune's beach line (fortune.pyx): the arcs left to right, as a doubly linked list and, once a site needs
# it, an AVL tree (in the Sweep's arrays); positions are given, never searched by key, except where a new
# site is located (exactly: parabola_order and coordinate comparisons), by a walk along the list from a
# hint, else down the tree. Inline helpers, compiled into the fortune module.
#
# A site is located in the arc whose half-open span [left breakpoint, right breakpoint) holds its x: at a
# breakpoint (a site on it, ties in degenerate input), the arc right of it, whichever way it is found. The
# spans are in order and cover the line, so that arc is one and the same for every walk and for the tree.
#
# The tree: with hints, walks settle nearly every site, and keeping an AVL tree balanced cost a tenth of
# the sweep. It is built (balanced, from the list, linear in the arcs) the first time a site needs it: when
# the walks' steps beyond the short ones pass a budget linear in the sites (sites far from every hint, as
# in clusters far apart), and from then on kept as before. Without hints it is kept from the start.

from libc.stdint cimport int8_t

from tvoronoi.kernels.parabola cimport parabola_order
from tvoronoi.kernels.sweep_state cimport Sweep, NONE

# ---------------------------------------------------------------------------------------------------------
# the AVL tree of arcs

cdef inline int h_of(Sweep* s, int v) noexcept nogil:
    return 0 if v == NONE else s.height[v]


cdef inline void fix_height(Sweep* s, int v) noexcept nogil:
    cdef int hl = h_of(s, s.left[v]), hr = h_of(s, s.right[v])
    s.height[v] = <int8_t>(1 + (hl if hl > hr else hr))


cdef inline void replace_child(Sweep* s, int p, int old, int new) noexcept nogil:
    if p == NONE:
        s.root = new
    elif s.left[p] == old:
        s.left[p] = new
    else:
        s.right[p] = new


cdef inline int rotate_left(Sweep* s, int x) noexcept nogil:
    cdef int y = s.right[x]
    s.right[x] = s.left[y]
    if s.left[y] != NONE:
        s.parent[s.left[y]] = x
    s.parent[y] = s.parent[x]
    replace_child(s, s.parent[x], x, y)
    s.left[y] = x
    s.parent[x] = y
    fix_height(s, x)
    fix_height(s, y)
    return y


cdef inline int rotate_right(Sweep* s, int x) noexcept nogil:
    cdef int y = s.left[x]
    s.left[x] = s.right[y]
    if s.right[y] != NONE:
        s.parent[s.right[y]] = x
    s.parent[y] = s.parent[x]
    replace_child(s, s.parent[x], x, y)
    s.right[y] = x
    s.parent[x] = y
    fix_height(s, x)
    fix_height(s, y)
    return y


cdef inline void rebalance_up(Sweep* s, int v) noexcept nogil:
    cdef int bal, before
    while v != NONE:
        before = s.height[v]
        fix_height(s, v)
        bal = h_of(s, s.left[v]) - h_of(s, s.right[v])
        if -1 <= bal <= 1 and s.height[v] == before:
            return          # this subtree's height did not change: nothing above it did

        if bal > 1:
            if h_of(s, s.left[s.left[v]]) < h_of(s, s.right[s.left[v]]):
                rotate_left(s, s.left[v])
            v = rotate_right(s, v)
        elif bal < -1:
            if h_of(s, s.right[s.right[v]]) < h_of(s, s.left[s.right[v]]):
                rotate_right(s, s.right[v])
            v = rotate_left(s, v)
        v = s.parent[v]


cdef inline int new_arc(Sweep* s, int site) noexcept nogil:
    cdef int a
    if s.n_free > 0:
        s.n_free -= 1
        a = s.free_arcs[s.n_free]
    else:
        a = s.n_arcs
        s.n_arcs += 1
    s.arc_site[a] = site
    s.arc_prev[a] = NONE
    s.arc_next[a] = NONE
    s.left[a] = NONE
    s.right[a] = NONE
    s.parent[a] = NONE
    s.height[a] = 1
    s.arc_event[a] = NONE
    s.arc_edge[a] = NONE
    return a


cdef inline void insert_after(Sweep* s, int x, int z) noexcept nogil:
    """Put arc z right after arc x, in the list and in the tree (when it is kept)."""
    cdef int y
    s.arc_prev[z] = x
    s.arc_next[z] = s.arc_next[x]
    if s.arc_next[x] != NONE:
        s.arc_prev[s.arc_next[x]] = z
    s.arc_next[x] = z
    if not s.tree_on:
        return
    if s.right[x] == NONE:
        s.right[x] = z
        s.parent[z] = x
    else:
        y = s.right[x]
        while s.left[y] != NONE:
            y = s.left[y]
        s.left[y] = z
        s.parent[z] = y
    rebalance_up(s, s.parent[z])


cdef inline void remove_arc(Sweep* s, int z) noexcept nogil:
    """Take arc z out of the list and the tree (when it is kept)."""
    if s.arc_prev[z] != NONE:
        s.arc_next[s.arc_prev[z]] = s.arc_next[z]
    else:
        s.first_arc = s.arc_next[z]
    if s.arc_next[z] != NONE:
        s.arc_prev[s.arc_next[z]] = s.arc_prev[z]
    if s.tree_on:
        unlink_from_tree(s, z)
    s.arc_site[z] = NONE
    s.free_arcs[s.n_free] = z
    s.n_free += 1


cdef inline void unlink_from_tree(Sweep* s, int z) noexcept nogil:
    cdef int y, zp, zl, zr, yp, yr, child, p
    cdef int8_t zh
    if s.left[z] != NONE and s.right[z] != NONE:
        # swap z with its successor y in the tree (y has no left child)
        y = s.right[z]
        while s.left[y] != NONE:
            y = s.left[y]
        zp = s.parent[z]; zl = s.left[z]; zr = s.right[z]; zh = s.height[z]
        yp = s.parent[y]; yr = s.right[y]
        replace_child(s, zp, z, y)
        s.parent[y] = zp
        s.left[y] = zl
        s.parent[zl] = y
        if yp == z:
            s.right[y] = z
            s.parent[z] = y
        else:
            s.right[y] = zr
            s.parent[zr] = y
            s.left[yp] = z
            s.parent[z] = yp
        s.left[z] = NONE
        s.right[z] = yr
        if yr != NONE:
            s.parent[yr] = z
        s.height[z] = s.height[y]
        s.height[y] = zh
    child = s.left[z] if s.left[z] != NONE else s.right[z]
    p = s.parent[z]
    replace_child(s, p, z, child)
    if child != NONE:
        s.parent[child] = p
    rebalance_up(s, p)


cdef inline int balanced_subtree(Sweep* s, int count, int* cursor) noexcept nogil:
    """The next count arcs of the list from cursor[0] on, as a subtree whose sides differ by one arc at
    most (so by one in height: an AVL tree); returns its root and moves the cursor past them."""
    cdef int v, l, r, hl, hr, n_left = count // 2
    if count == 0:
        return NONE
    l = balanced_subtree(s, n_left, cursor)
    v = cursor[0]
    cursor[0] = s.arc_next[v]
    r = balanced_subtree(s, count - 1 - n_left, cursor)
    s.left[v] = l
    s.right[v] = r
    if l != NONE:
        s.parent[l] = v
    if r != NONE:
        s.parent[r] = v
    hl = h_of(s, l)
    hr = h_of(s, r)
    s.height[v] = <int8_t>(1 + (hl if hl > hr else hr))
    return v


cdef inline void build_tree(Sweep* s) noexcept nogil:
    """The tree of the arcs in the list, balanced; kept from now on."""
    cdef int a = s.first_arc, count = 0, cursor
    while a != NONE:
        count += 1
        a = s.arc_next[a]
    cursor = s.first_arc
    s.root = balanced_subtree(s, count, &cursor)
    if s.root != NONE:
        s.parent[s.root] = NONE
    s.tree_on = True


# ---------------------------------------------------------------------------------------------------------
# locating a new site on the beach line

cdef inline int breakpoint_side(Sweep* s, int a, int b, double px, double py) noexcept nogil:
    """-1 if p is left of the breakpoint between arcs of sites a (left) and b, +1 right, 0 on it."""
    cdef double ax = s.x[a], ay = s.y[a], bx = s.x[b], by = s.y[b]
    cdef int o
    # of two parabolas, the narrower (its site nearer the sweep line) is above the
    # other between their two crossings, and its apex lies between them: the
    # breakpoint with a on the left is the right crossing if a is narrower
    if ay > by:
        if px <= ax:
            return -1
    elif by > ay:
        if px >= bx:
            return 1
    elif ay == py:
        return 1          # degenerate case: both on the sweep row; p comes after them
    o = parabola_order(ax, ay, bx, by, px, py)
    return -1 if o > 0 else (1 if o < 0 else 0)


cdef enum:
    WALK_MAX = 8        # arcs a walk from a hint may pass before it counts as a long one
    HINTS_TRIAL = 2048  # sites searched in the tree before the hints may be given up (most sites were)
    LONG_WALK_STEPS_PER_SITE = 2    # the budget of long walks' steps (and strips scanned for a hint):
    LONG_WALK_STEPS_BASE = 4096     # this many a site, and this many more, before the tree is built


cdef inline int hint_slot(Sweep* s, double px) noexcept nogil:
    """The strip of x that px lies in (0 .. n_hint - 1)."""
    cdef double f = (px - s.hint_x0) * s.hint_scale
    if not (f >= 0.0):
        return 0
    if f >= s.n_hint - 1:
        return s.n_hint - 1
    return <int> f


cdef inline void set_hint(Sweep* s, double x, int arc) noexcept nogil:
    """Arc (live) is where a site at x would be located now, or near it."""
    cdef int k
    if s.n_hint == 0:
        return              # no hints: every site down the tree
    k = hint_slot(s, x)
    s.hint[k] = arc
    s.hint_site[k] = s.arc_site[arc]


cdef inline bint hint_live(Sweep* s, int k) noexcept nogil:
    # strip k's arc is live (its slot may since have been freed, or reused for another site elsewhere)
    return s.hint[k] != NONE and s.arc_site[s.hint[k]] == s.hint_site[k]


cdef inline int walk_to_arc(Sweep* s, int h, double px, double py, long max_steps, long* taken) noexcept nogil:
    """The arc above p by a walk along the beach line from the live arc h: the arc whose span
    [left breakpoint, right breakpoint) holds p; NONE past max_steps arcs. Adds the arcs passed to
    taken[0]."""
    cdef int a, c, side
    cdef long k = 0
    # (a step left shows that p is left of the new arc's right breakpoint, a step right that it is not
    # left of its left one: neither is tested again)
    cdef bint left_known = False, right_known = False
    while k < max_steps:
        a = s.arc_prev[h]
        if a != NONE and not left_known:
            side = breakpoint_side(s, s.arc_site[a], s.arc_site[h], px, py)
            if side < 0:
                h = a
                right_known = True
                k += 1
                continue
        c = s.arc_next[h]
        if c != NONE and not right_known:
            side = breakpoint_side(s, s.arc_site[h], s.arc_site[c], px, py)
            if side >= 0:
                h = c
                left_known = True
                k += 1
                continue
        taken[0] += k
        return h
    taken[0] += k
    return NONE


cdef inline int nearest_live_hint(Sweep* s, int k, long* taken) noexcept nogil:
    """The live hint of the strip nearest to strip k (either side), else the first arc; adds the strips
    looked at to taken[0]."""
    cdef int d
    for d in range(1, s.n_hint):
        if k + d < s.n_hint and hint_live(s, k + d):
            taken[0] += d
            return s.hint[k + d]
        if k - d >= 0 and hint_live(s, k - d):
            taken[0] += d
            return s.hint[k - d]
    taken[0] += s.n_hint
    return s.first_arc


cdef inline int locate_hinted(Sweep* s, double px, double py) noexcept nogil:
    """locate_arc, by a short walk from the hint of p's strip (else of a strip beside it) when it holds a
    live arc and the walk settles; else, while the tree is not built, by a longer walk (from the nearest
    live hint) within the budget left; else down the tree. Counts each way in n_walks, n_long_walks and
    n_descents, and gives the hints up (n_hint = 0) once the tree has located more sites than the walks,
    past HINTS_TRIAL."""
    cdef int k, h, v
    cdef long taken = 0
    if s.n_hint == 0:
        s.n_descents += 1
        return locate_arc(s, px, py)
    k = hint_slot(s, px)
    if hint_live(s, k):
        h = s.hint[k]
    elif k + 1 < s.n_hint and hint_live(s, k + 1):
        h = s.hint[k + 1]
    elif k > 0 and hint_live(s, k - 1):
        h = s.hint[k - 1]
    else:
        h = NONE
    if h != NONE:
        v = walk_to_arc(s, h, px, py, WALK_MAX, &taken)
        if v != NONE:
            s.n_walks += 1
            return v
    if not s.tree_on:
        if h == NONE:
            h = nearest_live_hint(s, k, &taken)
        else:
            taken = 0       # (the short walk's steps are not counted against the budget)
        v = walk_to_arc(s, h, px, py, s.long_budget - taken, &taken)
        s.long_budget -= taken
        if v != NONE:
            s.n_long_walks += 1
            return v
        build_tree(s)
    s.n_descents += 1
    if s.n_descents > HINTS_TRIAL and s.n_descents > s.n_walks:
        s.n_hint = 0        # the strips do not fit these sites (clusters far apart): the tree alone from now
    return locate_arc(s, px, py)


cdef inline int locate_arc(Sweep* s, double px, double py) noexcept nogil:
    """The arc above p: the one whose span [left breakpoint, right breakpoint) holds p."""
    cdef int v = s.root, a, c, step
    while True:
        a = s.arc_prev[v]
        c = s.arc_next[v]
        step = 0
        if a != NONE and breakpoint_side(s, s.arc_site[a], s.arc_site[v], px, py) < 0:
            step = -1
        elif c != NONE and breakpoint_side(s, s.arc_site[v], s.arc_site[c], px, py) >= 0:
            step = 1
        if step == -1 and s.left[v] != NONE:
            v = s.left[v]
        elif step == 1 and s.right[v] != NONE:
            v = s.right[v]
        else:
            return v
