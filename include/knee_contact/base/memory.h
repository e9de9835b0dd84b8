#ifndef knee_contact_memory_h
#define knee_contact_memory_h

#include <string>

namespace knee_contact
{
  /**
   * What this process may still allocate, the one measure every estimate
   * checks against before it allocates (the mesh's cell count, a reader's
   * declared array sizes, the solver path, gmsh's address-space limit).
   */
  namespace memory
  {
    /**
     * Bytes this process can still allocate before the kernel refuses or
     * kills it: the least of MemAvailable, the cgroup's limit (v2 or v1)
     * less its usage, and the address-space limit (ulimit -v) less the
     * process's mapped size (unless not @p address_space: for another
     * process), the first two divided by the ranks of the run on this
     * machine. @p which names the binding limit.
     */
    double
    available(std::string &which, bool address_space = true);

    /** The process's mapped size (VmSize) [bytes], or -1. */
    double
    process_virtual();

    /** The process's peak resident memory so far (VmHWM) [MB], or -1. */
    double
    peak_resident_MB();

    /**
     * Gives the heap's free pages back to the system (glibc's malloc_trim;
     * elsewhere nothing). glibc keeps what a phase freed (rank 0's whole
     * mesh, the set-up's temporaries, an old hierarchy, the solve's
     * vectors) for what comes next, and the next phase's blocks often do
     * not fit into it: each AMG rebuild raised a rank's resident set by 10
     * to 90 MB at 1e6 dofs (doc/parallel.md).
     */
    void
    return_free_heap();

    /** "123 MB". */
    std::string
    megabytes(double bytes);

    /** The address-space limit (ulimit -v) [bytes], or infinity. */
    double
    address_space_limit();

    /** Whether an address-space limit (ulimit -v) is in force. */
    bool
    address_space_limited();

    /**
     * Make OpenBLAS safe under an address-space limit, at the start of
     * main(): OpenBLAS retries a failed allocation of its buffer (128 MB a
     * thread) forever (blas_memory_alloc), in a worker thread from its
     * start and in the calling thread at its first level-3 call; the
     * factorisation then waits for a worker that never comes, and exit()
     * joins it (measured: 7 hangs in 11 runs of a 300 x 300 block at
     * 1.2 GB). Under a limit: OpenBLAS on one thread (the workers are
     * never asked), the calling thread's buffer taken now, while there is
     * room (a 128 x 128 product), and a refusal if the limit leaves less
     * than two buffers. Without a limit nothing changes. The symbols are
     * looked up at run time: another BLAS has none of this.
     */
    void
    prepare_blas();
  } // namespace memory
} // namespace knee_contact

#endif
