#ifndef knee_contact_interruption_h
#define knee_contact_interruption_h

#include <sys/types.h>

#include <string>

namespace knee_contact
{
  /**
   * SIGINT, SIGTERM and SIGHUP stop a run at once, at any point (solve,
   * output, pictures): the handler kills a running external program (gmsh,
   * the picture script), removes the run's temporary folders and its lock
   * file, and exits with 128 + the signal number (130 for Ctrl-C, 143 for
   * SIGTERM). Everything it does is async-signal-safe (kill, waitpid,
   * getdents64, unlinkat, rmdir, _exit), so it may interrupt any code,
   * including a factorisation in another thread; the previous result set in
   * the output folder is never touched because a run writes only into its
   * own temporary folder until the final swap.
   *
   * Written by hand because no library here offers this; deal.II has no
   * signal handling.
   */
  namespace interruption
  {
    /** Install the handlers (once, at the start of main()). */
    void
    install();

    /**
     * Remove @p folder (everything below it, the folder itself) if a
     * signal arrives. At most a few folders can be registered.
     */
    void
    register_folder(const std::string &folder);

    void
    unregister_folder(const std::string &folder);

    /** The result set has replaced the output folder: a later signal
     * says so instead of "unchanged". */
    void
    results_written();

    /** The handler prints nothing (the ranks other than 0 of a parallel
     * run, which mpirun signals too). */
    void
    say_nothing();

    /**
     * Remove every registered folder and file now, as the handler would:
     * for a process that leaves by std::_Exit (out of memory, an
     * address-space limit), which skips the exit handlers. Allocates
     * nothing.
     */
    void
    remove_registered();

    /** Remove the file @p file if a signal arrives (the lock file). */
    void
    register_file(const std::string &file);

    void
    unregister_file(const std::string &file);

    /**
     * The process group of a running external program (gmsh, the picture
     * process), killed (SIGKILL) if a signal arrives; at most four at once.
     */
    void
    add_child(pid_t process_group);

    /** The program of @p process_group has ended. */
    void
    remove_child(pid_t process_group);
  } // namespace interruption
} // namespace knee_contact

#endif
