#include <knee_contact/core/external_program.h>
#include <knee_contact/core/interruption.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <thread>

extern char **environ;

namespace knee_contact
{
  ProgramResult
  run_program(const std::vector<std::string> &arguments,
              const std::string              &log,
              const double                    time_limit)
  {
    ProgramResult result;
    if (arguments.empty())
      return result;

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(
      &actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(
      &actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);

    // Its own process group (so the time limit and an interruption kill
    // gmsh's or python's children too), default signal dispositions and no
    // blocked signals.
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(&attributes,
                             POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF |
                               POSIX_SPAWN_SETSIGMASK);
    posix_spawnattr_setpgroup(&attributes, 0);
    sigset_t signals;
    sigemptyset(&signals);
    for (const int s : {SIGINT, SIGTERM, SIGHUP, SIGPIPE})
      sigaddset(&signals, s);
    posix_spawnattr_setsigdefault(&attributes, &signals);
    sigemptyset(&signals);
    posix_spawnattr_setsigmask(&attributes, &signals);

    std::vector<char *> argv;
    for (const auto &a : arguments)
      argv.push_back(const_cast<char *>(a.c_str()));
    argv.push_back(nullptr);

    // No interruption between the start and the registration of the child.
    sigset_t blocked, previous;
    sigemptyset(&blocked);
    for (const int s : {SIGINT, SIGTERM, SIGHUP})
      sigaddset(&blocked, s);
    pthread_sigmask(SIG_BLOCK, &blocked, &previous);
    pid_t      pid    = 0;
    const bool search = arguments[0].find('/') == std::string::npos;
    const int  status =
      search ? posix_spawnp(
                 &pid, argv[0], &actions, &attributes, argv.data(), environ)
              : posix_spawn(
                 &pid, argv[0], &actions, &attributes, argv.data(), environ);
    if (status == 0)
      interruption::set_child(pid);
    pthread_sigmask(SIG_SETMASK, &previous, nullptr);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    if (status != 0)
      return result;

    const auto start = std::chrono::steady_clock::now();
    int        wait_status;
    for (;;)
      {
        const pid_t done = waitpid(pid, &wait_status, WNOHANG);
        if (done == pid)
          break;
        if (done < 0 && errno != EINTR)
          {
            wait_status = 0;
            break;
          }
        const double elapsed = std::chrono::duration<double>(
                                 std::chrono::steady_clock::now() - start)
                                 .count();
        if (elapsed > time_limit)
          {
            kill(-pid, SIGKILL);
            while (waitpid(pid, &wait_status, 0) < 0 && errno == EINTR)
              ;
            result.timed_out = true;
            break;
          }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    // Its children may outlive it in its group; they must not write on.
    kill(-pid, SIGKILL);
    interruption::set_child(0);

    if (WIFEXITED(wait_status))
      result.exit_code = WEXITSTATUS(wait_status);
    else if (WIFSIGNALED(wait_status) && !result.timed_out)
      result.signal = WTERMSIG(wait_status);

    std::ifstream in(log);
    std::string   last;
    for (std::string line; std::getline(in, line);)
      {
        if (line.find("rror") != std::string::npos && result.message.empty())
          result.message = line;
        if (!line.empty())
          last = line;
      }
    if (result.message.empty())
      result.message = last;
    return result;
  }



  std::string
  describe_failure(const ProgramResult &result,
                   const std::string   &program,
                   const std::string   &file,
                   const std::string   &time_limit_parameter,
                   const double         time_limit)
  {
    std::string line = program + " failed on '" + file + "': ";
    if (result.timed_out)
      return line + "no result within " +
             std::to_string(static_cast<long>(time_limit)) + " s (" +
             time_limit_parameter + ")";
    if (result.exit_code < 0 && result.signal == 0)
      return line + "the program could not be started (is it installed?)";
    if (result.signal != 0)
      line += "killed by signal " + std::to_string(result.signal);
    else
      line += "exit code " + std::to_string(result.exit_code);
    if (!result.message.empty())
      line += ": " + result.message;
    return line;
  }
} // namespace knee_contact
