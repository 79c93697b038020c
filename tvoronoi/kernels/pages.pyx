"""Where a build's arrays live: large ones in pages mapped for them alone, handed back when they are freed.

A build allocates and frees a few hundred MiB of arrays of every size. The C library's heap keeps what is
freed for later (it raises its threshold for mapping a block of its own each time it unmaps one, up to
32 MiB), so a build's temporaries stay resident as holes that the next, larger arrays cannot use: at
1,000,000 sites that is 40-60 MiB of peak memory for nothing. numpy lets a context choose the allocator of
the arrays made in it (a data memory handler, NEP 49). ``mapped()`` installs one that maps each array of
1 MiB or more on its own (from 4 MiB on, advised for huge pages as numpy does, and starting on a huge
page's boundary, so that all its whole huge pages can be huge: the kernel places a mapping anywhere,
which left up to 2 MiB at either end to 4 KiB faults), unmaps it when it is freed,
and resizes it in place (mremap); smaller arrays come from malloc as before. An array remembers the handler
that made it, so arrays that outlive the build are freed correctly whenever they are.

In the checked build (AddressSanitizer) every array comes from malloc, so that the sanitizer sees them.
While a build runs, freed mappings (up to 32 MiB) are kept and given to the next large arrays, resized in
place: their pages are resident already, where a fresh mapping's are faulted in and zeroed by the kernel.
They are unmapped when the last ``mapped()`` block ends. ``trim_heap()`` hands back what the C library's heap holds freed (the kernels' own scratch comes from
malloc); a build calls it between phases.
"""

from contextlib import contextmanager

from cpython.pycapsule cimport PyCapsule_New
from libc.stdint cimport uintptr_t

from tvoronoi.kernels.populate cimport populate

cdef extern from *:
    """
    #include <stdint.h>
    #include <stdlib.h>
    #include <string.h>
    #include <numpy/ndarraytypes.h>
    #if defined(__unix__) && !defined(__SANITIZE_ADDRESS__)
    #include <sys/mman.h>
    #define TV_MAPS 1
    #else
    #define TV_MAPS 0
    #endif

    /* every block starts with a header of 64 bytes (the arrays keep numpy's 64-byte alignment):
       the length of its own mapping, 0 for a malloc'd block, and the size asked for */
    #define TV_HEAD 64
    #define TV_MAP_MIN ((size_t) 1 << 20)
    #define TV_HUGE_MIN ((size_t) 4 << 20)
    #define TV_HUGE_PAGE ((size_t) 2 << 20)
    /* 1 in a thread inside small_pages(): its fresh mappings are not advised for huge pages */
    static __thread int tv_small_pages = 0;

    #if TV_MAPS
    /* Mappings freed during a build are kept (up to TV_KEEP_BYTES) and given to the next large
       arrays, resized in place by the page tables (mremap): their pages are resident already, where a
       fresh mapping's must be faulted in and zeroed by the kernel, a third of a build's time on a
       virtual machine. They are unmapped when the last build leaves (tv_depth back to 0). */
    #include <pthread.h>
    #include <unistd.h>
    #define TV_KEEP_SLOTS 16
    #define TV_KEEP_BYTES ((size_t) 32 << 20)
    static pthread_mutex_t tv_lock = PTHREAD_MUTEX_INITIALIZER;
    static char* tv_kept[TV_KEEP_SLOTS];
    static size_t tv_kept_len[TV_KEEP_SLOTS];
    static int tv_n_kept = 0;
    static size_t tv_kept_bytes = 0;
    static int tv_depth = 0;

    /* a kept mapping for len bytes: the smallest that holds them, else the largest (grown); NULL if none */
    static char* tv_reuse(size_t len, size_t* had) {
        int k, best = -1;
        char* p;
        pthread_mutex_lock(&tv_lock);
        for (k = 0; k < tv_n_kept; k++) {
            if (best < 0) { best = k; continue; }
            if (tv_kept_len[k] >= len ? (tv_kept_len[best] < len || tv_kept_len[k] < tv_kept_len[best])
                                      : (tv_kept_len[best] < len && tv_kept_len[k] > tv_kept_len[best]))
                best = k;
        }
        if (best < 0) { pthread_mutex_unlock(&tv_lock); return NULL; }
        p = tv_kept[best];
        *had = tv_kept_len[best];
        tv_kept_bytes -= tv_kept_len[best];
        tv_n_kept--;
        tv_kept[best] = tv_kept[tv_n_kept];
        tv_kept_len[best] = tv_kept_len[tv_n_kept];
        pthread_mutex_unlock(&tv_lock);
        return p;
    }

    /* keep a freed mapping for reuse if a build is running and there is room; else unmap it */
    static void tv_release(char* p, size_t len) {
        pthread_mutex_lock(&tv_lock);
        if (tv_depth > 0 && tv_n_kept < TV_KEEP_SLOTS && tv_kept_bytes + len <= TV_KEEP_BYTES) {
            tv_kept[tv_n_kept] = p;
            tv_kept_len[tv_n_kept] = len;
            tv_n_kept++;
            tv_kept_bytes += len;
            pthread_mutex_unlock(&tv_lock);
            return;
        }
        pthread_mutex_unlock(&tv_lock);
        munmap(p, len);
    }

    static void tv_enter(void) {
        pthread_mutex_lock(&tv_lock);
        tv_depth++;
        pthread_mutex_unlock(&tv_lock);
    }

    static void tv_leave(void) {
        int k, n;
        char* gone[TV_KEEP_SLOTS];
        size_t gone_len[TV_KEEP_SLOTS];
        pthread_mutex_lock(&tv_lock);
        n = 0;
        if (--tv_depth == 0) {
            for (k = 0; k < tv_n_kept; k++) { gone[k] = tv_kept[k]; gone_len[k] = tv_kept_len[k]; }
            n = tv_n_kept;
            tv_n_kept = 0;
            tv_kept_bytes = 0;
        }
        pthread_mutex_unlock(&tv_lock);
        for (k = 0; k < n; k++) munmap(gone[k], gone_len[k]);
    }
    #else
    static void tv_enter(void) {}
    static void tv_leave(void) {}
    #endif

    #if TV_MAPS
    /* a fresh mapping of len bytes; from TV_HUGE_MIN on, advised for huge pages and starting on a
       huge page's boundary (the kernel would place it anywhere, leaving up to 2 MiB of its first and
       last huge pages to 4 KiB faults) */
    static char* tv_map(size_t len) {
        char* p;
    #ifdef MADV_HUGEPAGE
        if (len >= TV_HUGE_MIN && !tv_small_pages) {
            /* a huge page more than needed, then what lies before the first boundary and after the
               array's pages handed back */
            size_t page = (size_t) sysconf(_SC_PAGESIZE), plen = (len + page - 1) / page * page;
            char* a;
            p = (char*) mmap(NULL, plen + TV_HUGE_PAGE, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
            if (p == MAP_FAILED) return NULL;
            a = (char*) (((uintptr_t) p + TV_HUGE_PAGE - 1) & ~(uintptr_t) (TV_HUGE_PAGE - 1));
            if (a > p) munmap(p, (size_t) (a - p));
            munmap(a + plen, (size_t) (p + TV_HUGE_PAGE - a));
            madvise(a, len, MADV_HUGEPAGE);
            return a;
        }
    #endif
        p = (char*) mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        return p == MAP_FAILED ? NULL : p;
    }
    #endif

    static void* tv_block(size_t n, int zeroed) {
        char* p;
        size_t len = n + TV_HEAD, had = 0;
        if (len < n) return NULL;
    #if TV_MAPS
        if (len >= TV_MAP_MIN) {
    #if defined(MREMAP_MAYMOVE)
            p = tv_reuse(len, &had);
            if (p != NULL && had != len) {
                char* q = (char*) mremap(p, had, len, MREMAP_MAYMOVE);
                if (q == MAP_FAILED) { munmap(p, had); p = NULL; }
                else p = q;
            }
    #else
            p = NULL;
    #endif
            if (p != NULL) {
                if (zeroed) {
                    /* the old pages hold old data up to their end; a part grown past them is fresh */
                    size_t page = (size_t) sysconf(_SC_PAGESIZE), used = (had + page - 1) / page * page;
                    memset(p, 0, used < len ? used : len);
                }
                ((size_t*) p)[0] = len;
                ((size_t*) p)[1] = n;
                return p + TV_HEAD;
            }
            p = tv_map(len);
            if (p == NULL) return NULL;
            ((size_t*) p)[0] = len;
            ((size_t*) p)[1] = n;
            return p + TV_HEAD;
        }
    #endif
        p = (char*) (zeroed ? calloc(len, 1) : malloc(len));
        if (p == NULL) return NULL;
        ((size_t*) p)[0] = 0;
        ((size_t*) p)[1] = n;
        return p + TV_HEAD;
    }

    static void* tv_malloc(void* ctx, size_t n) { return tv_block(n, 0); }

    static void* tv_calloc(void* ctx, size_t nelem, size_t elsize) {
        if (elsize != 0 && nelem > ((size_t) -1) / elsize) return NULL;
        return tv_block(nelem * elsize, 1);          /* fresh mappings are zero */
    }

    static void tv_free(void* ctx, void* ptr, size_t size) {
        char* p;
        if (ptr == NULL) return;
        p = (char*) ptr - TV_HEAD;
    #if TV_MAPS
        if (((size_t*) p)[0] != 0) { tv_release(p, ((size_t*) p)[0]); return; }
    #endif
        free(p);
    }

    static void* tv_realloc(void* ctx, void* ptr, size_t n) {
        char *p, *q;
        size_t old, len = n + TV_HEAD;
        if (ptr == NULL) return tv_block(n, 0);
        if (len < n) return NULL;
        p = (char*) ptr - TV_HEAD;
        old = ((size_t*) p)[1];
    #if TV_MAPS && defined(MREMAP_MAYMOVE)
        if (((size_t*) p)[0] != 0) {             /* a mapping: moved or cut by the page tables, no copy */
            q = (char*) mremap(p, ((size_t*) p)[0], len, MREMAP_MAYMOVE);
            if (q == MAP_FAILED) return NULL;
            ((size_t*) q)[0] = len;
            ((size_t*) q)[1] = n;
            return q + TV_HEAD;
        }
    #endif
        if (((size_t*) p)[0] == 0 && len < TV_MAP_MIN) {
            q = (char*) realloc(p, len);
            if (q == NULL) return NULL;
            ((size_t*) q)[1] = n;
            return q + TV_HEAD;
        }
        q = (char*) tv_block(n, 0);
        if (q == NULL) return NULL;
        memcpy(q, ptr, old < n ? old : n);
        tv_free(ctx, ptr, old);
        return q;
    }

    /* what the C library's heap holds freed, handed back (glibc: malloc_trim) */
    #if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
    #include <malloc.h>
    static int tv_trim(void) { return malloc_trim(0); }
    #else
    static int tv_trim(void) { return 0; }
    #endif

    static PyDataMem_Handler tv_handler = {
        "tvoronoi_pages", 1, {NULL, tv_malloc, tv_calloc, tv_realloc, tv_free}
    };
    """
    ctypedef struct PyDataMem_Handler:
        pass
    PyDataMem_Handler tv_handler
    int TV_MAPS
    int tv_trim() nogil
    void tv_enter() nogil
    void tv_leave() nogil
    int tv_small_pages

cdef extern from "numpy/arrayobject.h":
    void _import_array() except *
    object PyDataMem_SetHandler(object handler)

_import_array()

HANDLER = PyCapsule_New(<void*> &tv_handler, "mem_handler", NULL)
MAPS = bool(TV_MAPS)


@contextmanager
def mapped():
    """Arrays made in this block (in this thread or task) come from the mapping handler above."""
    old = PyDataMem_SetHandler(HANDLER)
    tv_enter()
    try:
        yield
    finally:
        PyDataMem_SetHandler(old)
        tv_leave()


@contextmanager
def small_pages():
    """Fresh mappings made in this block, in this thread, are not advised for huge pages: their pages come
    one by one from the system's lists of small free pages. On a virtual machine whose host takes back
    memory left free (here, in blocks of 8 MiB), a huge page is most often taken from such a block, and
    the host gives it back slowly; with two threads faulting at once, huge pages cost a build more than
    they save (tvoronoi.build: at 10^6 uniform sites, builds on two threads 10-50 ms faster without
    them, on one 6-50 ms slower)."""
    global tv_small_pages
    was = tv_small_pages
    tv_small_pages = 1
    try:
        yield
    finally:
        tv_small_pages = was


def small_pages_on():
    """True inside small_pages() in this thread (a thread working for this one applies it too)."""
    return bool(tv_small_pages)


def trim_heap():
    """Hand back to the system what the C library's heap holds freed (glibc's malloc_trim; elsewhere
    nothing). The kernels' own scratch (the BRIO items, the Z-curve keys, the clipper's buffers) comes
    from malloc, and glibc keeps large freed blocks in its heap once it has raised its threshold for
    mapping them: a build calls this between its phases, so that the next phase's peak does not stand
    on them (at 10^6 sites by halves, 36 MiB). Returns True if memory was handed back."""
    cdef int released
    with nogil:
        released = tv_trim()
    return bool(released)


def populate_pages(a):
    """Fault in the whole pages of C-contiguous array ``a`` in one call (populate.pxd, as the kernels do
    for the arrays they write whole); its contents stay as they are. Exposed for tests."""
    if not a.flags.c_contiguous:
        raise ValueError("populate_pages: the array must be C-contiguous")
    cdef uintptr_t address = a.__array_interface__["data"][0]
    cdef size_t length = a.nbytes
    with nogil:
        populate(<void*> address, length)

