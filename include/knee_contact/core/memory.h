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
     * process's mapped size. @p which names the binding limit.
     */
    double
    available(std::string &which);

    /** The process's mapped size (VmSize) [bytes], or -1. */
    double
    process_virtual();

    /** "123 MB". */
    std::string
    megabytes(double bytes);
  } // namespace memory
} // namespace knee_contact

#endif
