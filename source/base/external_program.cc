#include <knee_contact/base/external_program.h>
#include <knee_contact/base/interruption.h>

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

extern char **environ;

namespace knee_contact
{
  namespace
  {
    // posix_spawn @p arguments with @p actions in a process group of its
    // own (so a time limit and an interruption kill its children too), with
    // default signal dispositions and no blocked signals; registered with
    // the interruption handler before any signal can arrive. 0 if it cannot
    // be started.
    pid_t
    spawn(const std::vector<std::string>   &arguments,
          const posix_spawn_file_actions_t &actions)
    {
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
        interruption::add_child(pid);
      pthread_sigmask(SIG_SETMASK, &previous, nullptr);
      posix_spawnattr_destroy(&attributes);

      return status == 0 ? pid : 0;
    }



    // The first line of a program's output that holds "rror", else the
    // last one that is not empty.
    std::string
    message_of(std::istream &in)
    {
      std::string message, last;
      for (std::string line; std::getline(in, line);)
        {
          if (line.find("rror") != std::string::npos && message.empty())
            message = line;
          if (!line.empty())
            last = line;
        }
      return message.empty() ? last : message;
    }



    // Wait for @p pid's end, at most @p time_limit seconds; then kill its
    // process group (and set @p timed_out). Its children may outlive it in
    // its group: they are killed too, they must not write on. Returns the
    // wait status; the process is no longer registered for interruptions.
    int
    wait_at_most(const pid_t pid, const double time_limit, bool &timed_out)
    {
      const auto start       = std::chrono::steady_clock::now();
      int        wait_status = 0;
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
          if (std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                            start)
                .count() > time_limit)
            {
              kill(-pid, SIGKILL);
              while (waitpid(pid, &wait_status, 0) < 0 && errno == EINTR)
                ;
              timed_out = true;
              break;
            }
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
      kill(-pid, SIGKILL);
      interruption::remove_child(pid);
      return wait_status;
    }



    void
    set_status(const int wait_status, ProgramResult &result)
    {
      if (WIFEXITED(wait_status))
        result.exit_code = WEXITSTATUS(wait_status);
      else if (WIFSIGNALED(wait_status) && !result.timed_out)
        result.signal = WTERMSIG(wait_status);
    }
  } // namespace



  ProgramResult
  run_program(const std::vector<std::string> &arguments,
              const std::string              &log,
              const double                    time_limit,
              const double                    memory_limit)
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
    const pid_t pid = spawn(arguments, actions);
    posix_spawn_file_actions_destroy(&actions);
    if (pid <= 0)
      return result;
    // posix_spawn returns once the program runs: it has allocated nothing
    // of its work yet.
    if (memory_limit > 0)
      {
        const rlimit limit{static_cast<rlim_t>(memory_limit),
                           static_cast<rlim_t>(memory_limit)};
        prlimit(pid, RLIMIT_AS, &limit, nullptr);
      }

    const int wait_status = wait_at_most(pid, time_limit, result.timed_out);

    set_status(wait_status, result);
    std::ifstream in(log);
    result.message = message_of(in);
    result.out_of_memory =
      memory_limit > 0 && !result.timed_out && result.exit_code != 0 &&
      (result.message.find("bad_alloc") != std::string::npos ||
       result.message.find("out of memory") != std::string::npos ||
       result.signal == SIGABRT || result.signal == SIGSEGV);
    return result;
  }



  bool
  HelperProcess::start(const std::vector<std::string> &arguments)
  {
    if (arguments.empty() || pid > 0)
      return false;
    int ends[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0)
      return false;
    // The log has no name: it cannot be left behind, whatever ends the run.
    const char       *tmpdir    = std::getenv("TMPDIR");
    const std::string directory = tmpdir && *tmpdir ? tmpdir : "/tmp";
    log = open(directory.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (log < 0)
      {
        std::string name = directory + "/knee_contact_pictures_XXXXXX";
        log              = mkostemp(name.data(), O_CLOEXEC);
        if (log >= 0)
          unlink(name.c_str());
      }
    if (log < 0)
      {
        close(ends[0]);
        close(ends[1]);
        return false;
      }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, ends[1], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, ends[1], 3);
    posix_spawn_file_actions_adddup2(&actions, log, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, log, STDERR_FILENO);
    pid = spawn(arguments, actions);
    posix_spawn_file_actions_destroy(&actions);
    close(ends[1]);
    socket = ends[0];
    if (pid <= 0)
      {
        pid = 0;
        stop(nullptr, true);
        return false;
      }
    return true;
  }



  ProgramResult
  HelperProcess::request(const std::vector<std::string> &fields,
                         const double                    time_limit)
  {
    ProgramResult result;
    if (pid <= 0)
      {
        result.message = "the picture process has ended";
        return result;
      }
    std::string message;
    for (const auto &field : fields)
      message += field + '\0';
    // MSG_NOSIGNAL: a helper that has died is an answer, not a SIGPIPE.
    for (std::size_t sent = 0; sent < message.size();)
      {
        const ssize_t n = send(socket,
                               message.data() + sent,
                               message.size() - sent,
                               MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR)
          continue;
        if (n <= 0)
          {
            stop(&result, false);
            return result;
          }
        sent += n;
      }

    const auto start = std::chrono::steady_clock::now();
    for (;;)
      {
        const auto end = buffer.find('\n');
        if (end != std::string::npos)
          {
            const std::string answer = buffer.substr(0, end);
            buffer.erase(0, end + 1);
            result.exit_code = answer == "ok" ? 0 : 1;
            if (answer.rfind("error: ", 0) == 0)
              result.message = answer.substr(7);
            return result;
          }
        const double left =
          time_limit - std::chrono::duration<double>(
                         std::chrono::steady_clock::now() - start)
                         .count();
        if (left <= 0)
          {
            result.timed_out = true;
            stop(&result, true);
            return result;
          }
        pollfd    wait_for{socket, POLLIN, 0};
        const int ready =
          poll(&wait_for, 1, static_cast<int>(std::min(left, 1.0) * 1000) + 1);
        if (ready < 0 && errno != EINTR)
          {
            stop(&result, true);
            return result;
          }
        if (ready <= 0)
          continue;
        char          chunk[4096];
        const ssize_t n = recv(socket, chunk, sizeof(chunk), 0);
        if (n < 0 && errno == EINTR)
          continue;
        if (n <= 0)
          {
            // It ended without an answer: its status and log say why.
            stop(&result, false);
            return result;
          }
        buffer.append(chunk, n);
      }
  }



  void
  HelperProcess::stop(ProgramResult *result, const bool kill_now)
  {
    // Closing the socket ends its input: a helper that is still there ends
    // on its own; one that does not within 5 s is killed.
    if (socket >= 0)
      close(socket);
    socket = -1;
    if (pid > 0)
      {
        if (kill_now)
          kill(-pid, SIGKILL);
        bool      killed      = false;
        const int wait_status = wait_at_most(pid, 5, killed);
        pid                   = 0;
        if (result)
          set_status(wait_status, *result);
      }
    if (log >= 0)
      {
        if (result && result->message.empty())
          {
            std::string text;
            char        chunk[4096];
            for (off_t offset = 0;;)
              {
                const ssize_t n = pread(log, chunk, sizeof(chunk), offset);
                if (n <= 0)
                  break;
                text.append(chunk, n);
                offset += n;
              }
            std::istringstream in(text);
            result->message = message_of(in);
          }
        close(log);
        log = -1;
      }
  }



  HelperProcess::~HelperProcess()
  {
    // No request is waiting for an answer here (requests are synchronous):
    // what it does now (its start, when a run fails early) is not needed.
    stop(nullptr, true);
  }



  std::string
  describe_failure(const ProgramResult &result,
                   const std::string   &program,
                   const std::string   &file,
                   const std::string   &time_limit_parameter,
                   const double         time_limit,
                   const std::string   &memory_limit_parameter,
                   const double         memory_limit)
  {
    std::string line = program + " failed on '" + file + "': ";
    if (result.out_of_memory)
      return line + "it ran out of the " +
             std::to_string(static_cast<long>(memory_limit / 1048576.)) +
             " MB it may use (" + memory_limit_parameter +
             "; a finer mesh than this machine can solve?)";
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
