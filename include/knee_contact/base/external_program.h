#ifndef knee_contact_external_program_h
#define knee_contact_external_program_h

#include <sys/types.h>

#include <string>
#include <vector>

namespace knee_contact
{
  /**
   * What an external program left behind.
   */
  struct ProgramResult
  {
    /** Exit code, or -1 if the program could not be started. */
    int exit_code = -1;
    /** Killed at the time limit. */
    bool timed_out = false;
    /** Killed by a signal (other than at the time limit). */
    int signal = 0;
    /** The first line of its output that holds "rror", else the last. */
    std::string message;
    /**
     * Ended by an allocation that failed under its memory limit
     * (std::bad_alloc, "out of memory", or killed by SIGABRT or SIGSEGV
     * while limited).
     */
    bool out_of_memory = false;
  };

  /**
   * Run @p arguments[0] (found on PATH if it has no '/') with the argument
   * vector @p arguments: posix_spawn, never a shell, so no value of a scene
   * can be read as a command. Standard output and error go to @p log; the
   * program runs in its own process group, is killed (with its children)
   * after @p time_limit seconds, and is killed as well if the run is
   * interrupted (see interruption.h). A @p memory_limit above 0 [bytes]
   * bounds its address space (prlimit RLIMIT_AS, set as it starts): an
   * allocation beyond fails in the program instead of growing until the
   * machine swaps or the kernel kills something.
   */
  ProgramResult
  run_program(const std::vector<std::string> &arguments,
              const std::string              &log,
              const double                    time_limit,
              const double                    memory_limit = 0);

  /**
   * A helper program that lives as long as a run and serves requests: the
   * picture process (scripts/pictures.py), started before the solve so that
   * Python's start overlaps it. Started like run_program() (posix_spawn, no
   * shell, its own process group, killed on an interruption); its standard
   * input and file descriptor 3 are one end of a socket pair: a request is
   * a list of fields, each sent followed by a NUL byte (a path cannot hold
   * one), an answer is one line, "ok" or "error: ...". Its standard output
   * and error go to a file that has no name (nothing is left behind), read
   * back for the message of a failure.
   *
   * Written by hand: neither deal.II nor the C++ library has a child
   * process with pipes.
   */
  class HelperProcess
  {
  public:
    /**
     * Start @p arguments; false (and no process) if it cannot be started.
     */
    bool
    start(const std::vector<std::string> &arguments);

    /** Running, and answering so far. */
    bool
    running() const
    {
      return pid > 0;
    }

    /**
     * Send @p fields and wait for the answer at most @p time_limit seconds.
     * No answer in time kills the process; then, or if it has ended, the
     * result gives its exit code or signal and the message of its log, and
     * it is no longer running().
     */
    ProgramResult
    request(const std::vector<std::string> &fields, const double time_limit);

    /** Kill it: no request waits for an answer at its end. */
    ~HelperProcess();

  private:
    void
    stop(ProgramResult *result, const bool kill_now);

    pid_t       pid    = 0;
    int         socket = -1;
    int         log    = -1;
    std::string buffer;
  };

  /**
   * One line for a failed run of @p program on @p file: "gmsh failed on
   * 'x.geo': ...", "... did not finish within 300 s (Mesh/Gmsh time
   * limit)", "... ran out of the 6000 MB it may use (Mesh/Gmsh memory
   * limit)", "... could not be started".
   */
  std::string
  describe_failure(const ProgramResult &result,
                   const std::string   &program,
                   const std::string   &file,
                   const std::string   &time_limit_parameter,
                   const double         time_limit,
                   const std::string   &memory_limit_parameter = "",
                   const double         memory_limit           = 0);
} // namespace knee_contact

#endif
