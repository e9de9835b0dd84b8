#ifndef knee_contact_external_program_h
#define knee_contact_external_program_h

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
  };

  /**
   * Run @p arguments[0] (found on PATH if it has no '/') with the argument
   * vector @p arguments: posix_spawn, never a shell, so no value of a scene
   * can be read as a command. Standard output and error go to @p log; the
   * program runs in its own process group, is killed (with its children)
   * after @p time_limit seconds, and is killed as well if the run is
   * interrupted (see interruption.h).
   */
  ProgramResult
  run_program(const std::vector<std::string> &arguments,
              const std::string              &log,
              const double                    time_limit);

  /**
   * One line for a failed run of @p program on @p file: "gmsh failed on
   * 'x.geo': ...", "... did not finish within 300 s (Mesh/Gmsh time
   * limit)", "... could not be started".
   */
  std::string
  describe_failure(const ProgramResult &result,
                   const std::string   &program,
                   const std::string   &file,
                   const std::string   &time_limit_parameter,
                   const double         time_limit);
} // namespace knee_contact

#endif
