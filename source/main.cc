#include <knee_contact/base/input.h>
#include <knee_contact/base/interruption.h>
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/base/progress.h>
#include <knee_contact/core/problem.h>

#include <deal.II/base/multithread_info.h>

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <new>
#include <stdexcept>
#include <system_error>

// knee_contact: unilateral contact between linear elastic bodies in 2D and
// 3D (the dimension comes from the mesh), on one process or under mpirun.
// Usage: [mpirun -np N] knee_contact [--dry-run] scene.prm | --help |
// --print-parameters
namespace
{
  // One line, then leave without the library destructors: with the address
  // space exhausted, OpenBLAS's worker threads retry their buffer
  // allocation forever and its exit handler joins them, so a normal return
  // hangs (measured: 10 minutes at 100 % CPU after the message). Everything
  // of this run that lives on disk was already cleaned up during the
  // unwinding that brought the exception here.
  [[noreturn]] void
  out_of_memory()
  {
    std::cerr << "knee_contact: error: out of memory (the mesh or the "
                 "factorisation needs more than this machine has; use "
                 "fewer refinements or a coarser mesh)"
              << std::endl;
    std::cout.flush();
    // What the exit handlers would remove (the iterative path's MPI
    // session folder).
    knee_contact::interruption::remove_registered();
    std::_Exit(knee_contact::ExitCode::input_error);
  }

  /**
   * deal.II reads DEAL_II_NUM_THREADS while its library is loaded, before
   * main(), and a value it cannot read (empty, a word, 0) ends the program
   * by an uncaught exception: an abort with a page of text. Checked first
   * here: an executable's .preinit_array runs before the initialisers of
   * the shared libraries it loads (System V ABI), before libc is set up:
   * only the environment it is given, write() and _exit() are used. Under
   * mpirun rank 0 alone prints (every rank leaves).
   */
  void
  check_thread_variable(int, char **, char **environment)
  {
    // (getenv() may not work yet: libc has not set its environ.)
    const auto variable = [environment](const char *name) -> const char * {
      const std::size_t length = std::strlen(name);
      for (char **e = environment; e != nullptr && *e != nullptr; ++e)
        if (std::strncmp(*e, name, length) == 0 && (*e)[length] == '=')
          return *e + length + 1;
      return nullptr;
    };
    const char *value = variable("DEAL_II_NUM_THREADS");
    if (value == nullptr)
      return;
    // What deal.II reads: an integer, with blanks around it; a positive
    // one of at most 9 digits is taken here.
    const char *c = value;
    while (*c == ' ' || *c == '\t')
      ++c;
    if (*c == '+')
      ++c;
    unsigned int digits = 0, nonzero = 0;
    for (; *c >= '0' && *c <= '9'; ++c, ++digits)
      nonzero += *c != '0';
    while (*c == ' ' || *c == '\t')
      ++c;
    if (*c == '\0' && digits > 0 && digits <= 9 && nonzero > 0)
      return;
    const char *rank = variable("OMPI_COMM_WORLD_RANK");
    if (rank == nullptr || std::strcmp(rank, "0") == 0)
      {
        char   line[200] = "knee_contact: error: environment variable "
                           "DEAL_II_NUM_THREADS = '";
        size_t n         = std::strlen(line);
        // The value, printable characters only, cut at 40.
        for (const char *v = value; *v != '\0' && v - value < 40; ++v)
          line[n++] = (*v >= ' ' && *v <= '~') ? *v : '?';
        const char tail[] = "' is not a positive number of threads (unset "
                            "it to use every core)\n";
        std::memcpy(line + n, tail, sizeof(tail) - 1);
        n += sizeof(tail) - 1;
        [[maybe_unused]] const auto written = ::write(2, line, n);
      }
    ::_exit(knee_contact::ExitCode::input_error);
  }

  [[gnu::used, gnu::section(".preinit_array")]] void (
      *const check_thread_variable_first)(int,
                                          char **,
                                          char **) = &check_thread_variable;

  /** The run; a failure's one-line @p message is printed by the caller. */
  int
  run(int argc, char **argv, std::string &message);
} // namespace

int
main(int argc, char **argv)
{
  // Under mpirun every rank starts MPI at once; rank 0 alone prints.
  if (knee_contact::parallel::launched_by_mpirun())
    {
      knee_contact::parallel::ensure_initialised();
      knee_contact::parallel::quiet_other_ranks();
    }
  std::string message;
  int         code = run(argc, argv, message);
  // Printed once; a rank that failed alone ends the others (30 s after the
  // failure: the replicated work reaches a failure of the input on every
  // rank within the same step).
  code = knee_contact::parallel::finish(code, message, 30.);
  // Under an address-space limit an OpenBLAS worker may be stuck retrying
  // its buffer (see memory::prepare_blas()), and exit() would join it:
  // leave without the exit handlers (the results are on disk, the streams
  // flushed).
  if (knee_contact::memory::address_space_limited())
    {
      std::cout.flush();
      std::cerr.flush();
      knee_contact::interruption::remove_registered();
      std::_Exit(code);
    }
  return code;
}

namespace
{
  int
  run(int argc, char **argv, std::string &message)
  {
    using namespace knee_contact;
    const std::string usage =
      "usage: knee_contact SCENE.prm       solve the scene, results in its "
      "output folder\n"
      "       knee_contact --dry-run SCENE.prm  read the scene and build its "
      "mesh, no solve\n"
      "       knee_contact --print-parameters   every parameter with its "
      "documentation and default\n"
      "       knee_contact --help\n";
    interruption::install();
    Progress::start_clock();
    try
      {
        memory::prepare_blas();
        if (argc == 2 && (std::strcmp(argv[1], "--help") == 0 ||
                          std::strcmp(argv[1], "-h") == 0))
          {
            std::cout << usage;
            return ExitCode::success;
          }
        if (argc == 2 && std::strcmp(argv[1], "--print-parameters") == 0)
          {
            // The 2D scene format; in 3D the vectors have a z component.
            ContactProblem<2>::print_parameters(std::cout);
            return ExitCode::success;
          }
        if (argc == 3 && std::strcmp(argv[1], "--dry-run") == 0)
          {
            if (scene_dimension(argv[2]) == 3)
              ContactProblem<3>(argv[2]).check_scene();
            else
              ContactProblem<2>(argv[2]).check_scene();
            return ExitCode::success;
          }
        if (argc != 2 || argv[1][0] == '-')
          {
            message = "knee_contact: error: expected one scene file; see "
                      "knee_contact --help";
            return ExitCode::input_error;
          }
        if (scene_dimension(argv[1]) == 3)
          return ContactProblem<3>(argv[1]).run();
        return ContactProblem<2>(argv[1]).run();
      }
    // A message built for the user (ExcMessage from AssertThrow, or a
    // runtime_error of the input checks) is bad input; out of memory is said
    // as such; anything else is a bug of the program.
    catch (const dealii::StandardExceptions::ExcMessage &exc)
      {
        std::ostringstream info;
        exc.print_info(info);
        message = "knee_contact: error: " + input::one_line(info.str());
        return ExitCode::input_error;
      }
    catch (const std::bad_alloc &)
      {
        out_of_memory();
      }
    catch (const std::system_error &exc)
      {
        // A thread that could not be started (EAGAIN or ENOMEM: its stack
        // could not be mapped) is out of memory too; it said "Resource
        // temporarily unavailable".
        if (exc.code() == std::errc::resource_unavailable_try_again ||
            exc.code() == std::errc::not_enough_memory)
          out_of_memory();
        message = "knee_contact: error: " + input::one_line(exc.what());
        return ExitCode::input_error;
      }
    catch (const dealii::ExceptionBase &exc)
      {
        std::ostringstream info;
        exc.print_info(info);
        message =
          "knee_contact: internal error (a bug; please report it "
          "with the scene file): " +
          input::one_line(exc.get_exc_name() + std::string(": ") + info.str());
        return ExitCode::internal_error;
      }
    catch (const std::runtime_error &exc)
      {
        message = "knee_contact: error: " + input::one_line(exc.what());
        return ExitCode::input_error;
      }
    catch (const std::exception &exc)
      {
        message = "knee_contact: internal error (a bug; please report it "
                  "with the scene file): " +
                  input::one_line(exc.what());
        return ExitCode::internal_error;
      }
    catch (...)
      {
        message = "knee_contact: internal error (a bug; please report it "
                  "with the scene file): unknown exception";
        return ExitCode::internal_error;
      }
  }
} // namespace
