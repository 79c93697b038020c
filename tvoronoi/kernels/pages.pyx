"""Where a build's arrays live: large ones in pages mapped for them alone, handed back when they are freed.

A build allocates and frees a few hundred MiB of arrays of every size. The C library's heap keeps what is
freed for later (it raises its threshold for mapping a block of its own each time it unmaps one, up to
32 MiB), so a build's temporaries stay resident as holes that the next, larger arrays cannot use: at
1,000,000 sites that is 40-60 MiB of peak memory for nothing. numpy lets a context choose the allocator of
the arrays made in it (a data memory handler, NEP 49). ``mapped()`` installs one that maps each array of
1 MiB or more on its own (with numpy's own advice for huge pages from 4 MiB), unmaps it when it is freed,
and resizes it in place (mremap); smaller arrays come from malloc as before. An array remembers the handler
that made it, so arrays that outlive the build are freed correctly whenever they are.

In the checked build (AddressSanitizer) every array comes from malloc, so that the sanitizer sees them.
``trim_heap()`` hands back what the C library's heap holds freed (the kernels' own scratch comes from
malloc); a build calls it between phases.
"""

from contextlib import contextmanager

from cpython.pycapsule cimport PyCapsule_New

cdef extern from *:
    """
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

    static void* tv_block(size_t n, int zeroed) {
        char* p;
        size_t len = n + TV_HEAD;
        if (len < n) return NULL;
    #if TV_MAPS
        if (len >= TV_MAP_MIN) {
            p = (char*) mmap(NULL, len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
            if (p == MAP_FAILED) return NULL;
    #ifdef MADV_HUGEPAGE
            if (len >= TV_HUGE_MIN) madvise(p, len, MADV_HUGEPAGE);
    #endif
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
        if (((size_t*) p)[0] != 0) { munmap(p, ((size_t*) p)[0]); return; }
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
    try:
        yield
    finally:
        PyDataMem_SetHandler(old)


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
