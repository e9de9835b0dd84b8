#include <knee_contact/base/interruption.h>

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <ctime>

namespace knee_contact
{
  namespace interruption
  {
    namespace
    {
      // Paths live in fixed buffers: the handler must not allocate. A slot
      // is in use while its first character is not '\0'.
      constexpr unsigned int max_paths  = 8;
      constexpr std::size_t  max_length = 4096;
      char                   folders[max_paths][max_length];
      char                   files[max_paths][max_length];
      // The process groups of running external programs (gmsh, the
      // picture process): at most two at once, a slot is free at 0.
      constexpr unsigned int max_children = 4;
      std::atomic<pid_t>     children[max_children];

      void
      put(char (&slots)[max_paths][max_length], const std::string &path)
      {
        if (path.empty() || path.size() + 1 > max_length)
          return;
        for (auto &slot : slots)
          if (slot[0] == '\0')
            {
              // The first character last: the handler never sees half a
              // path.
              std::memcpy(slot + 1, path.c_str() + 1, path.size());
              std::atomic_signal_fence(std::memory_order_seq_cst);
              slot[0] = path[0];
              return;
            }
      }

      void
      take(char (&slots)[max_paths][max_length], const std::string &path)
      {
        for (auto &slot : slots)
          if (path == slot)
            slot[0] = '\0';
      }

      // Remove @p folder and everything below it (a friction load path
      // stages a folder per case, the pictures a folder of their own), with
      // system calls only: readdir and std::filesystem may allocate,
      // getdents64, unlinkat and openat do not. Entries of the folder @p
      // parent names relative to it (AT_FDCWD for a path). The depth is
      // bounded: our own staging is three levels deep at most, and a
      // bounded recursion keeps the handler's stack use bounded too (2 kB
      // a level). Returns whether the folder is gone.
      bool
      remove_tree(const int parent, const char *folder, const unsigned depth)
      {
        if (depth > 16)
          return false;
        const int fd = openat(parent,
                              folder,
                              O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (fd >= 0)
          {
            // Removing entries while reading the folder may skip some:
            // read it again until a pass removes nothing.
            for (bool removed = true; removed;)
              {
                removed = false;
                lseek(fd, 0, SEEK_SET);
                alignas(8) char buffer[2048];
                long            n;
                while (
                  (n = syscall(SYS_getdents64, fd, buffer, sizeof(buffer))) > 0)
                  for (long offset = 0; offset < n;)
                    {
                      // struct linux_dirent64: ino (8), off (8), reclen (2),
                      // type (1), name.
                      unsigned short length;
                      std::memcpy(&length,
                                  buffer + offset + 16,
                                  sizeof(length));
                      const char *name = buffer + offset + 19;
                      offset += length;
                      if (std::strcmp(name, ".") == 0 ||
                          std::strcmp(name, "..") == 0)
                        continue;
                      if (unlinkat(fd, name, 0) == 0)
                        removed = true;
                      else if ((errno == EISDIR || errno == EPERM) &&
                               remove_tree(fd, name, depth + 1))
                        removed = true;
                    }
              }
            close(fd);
          }
        return unlinkat(parent, folder, AT_REMOVEDIR) == 0;
      }

      void
      remove_folders_and_files()
      {
        for (const auto &folder : folders)
          if (folder[0] != '\0')
            remove_tree(AT_FDCWD, folder, 0);
        for (const auto &file : files)
          if (file[0] != '\0')
            unlink(file);
      }

      /** Set on the ranks other than 0 of a parallel run: one says it. */
      volatile sig_atomic_t quiet = 0;
      /** Set once the result set has replaced the output folder. */
      volatile sig_atomic_t written = 0;

      void
      handle(const int signal)
      {
        for (auto &child : children)
          {
            const pid_t group = child.load();
            if (group > 0)
              {
                kill(-group, SIGKILL);
                while (waitpid(group, nullptr, 0) < 0 && errno == EINTR)
                  ;
              }
          }
        remove_folders_and_files();
        const char unchanged[] = "knee_contact: interrupted by a signal; "
                                 "the output folder is unchanged\n";
        const char complete[]  = "knee_contact: interrupted by a signal "
                                 "after its results were written\n";
        if (!quiet) [[maybe_unused]]
          const auto said =
            written ? write(STDERR_FILENO, complete, sizeof(complete) - 1)
                    : write(STDERR_FILENO, unchanged, sizeof(unchanged) - 1);
        // A rank other than 0 leaves after rank 0 has removed the staging
        // folder (a load path's holds a folder per case): mpirun ends the
        // job with SIGKILL once one rank has left, and rank 0 killed in
        // its cleanup left its staging folder and lock (measured, 1001
        // cases). It waits at most 5 s (nanosleep is async-signal-safe).
        if (quiet)
          {
            struct timespec wait = {5, 0};
            while (nanosleep(&wait, &wait) != 0 && errno == EINTR)
              ;
          }
        _exit(128 + signal);
      }
    } // namespace



    void
    install()
    {
      struct sigaction action;
      std::memset(&action, 0, sizeof(action));
      action.sa_handler = handle;
      sigfillset(&action.sa_mask);
      // SIGPIPE too: a run whose output goes to a reader that left
      // (`knee_contact scene.prm | head`) was ended by the default action
      // and left its staging folder and lock beside the output folder.
      for (const int signal : {SIGINT, SIGTERM, SIGHUP, SIGPIPE})
        sigaction(signal, &action, nullptr);
    }



    void
    say_nothing()
    {
      quiet = 1;
    }



    void
    results_written()
    {
      written = 1;
    }



    void
    remove_registered()
    {
      remove_folders_and_files();
    }



    void
    register_folder(const std::string &folder)
    {
      put(folders, folder);
    }



    void
    unregister_folder(const std::string &folder)
    {
      take(folders, folder);
    }



    void
    register_file(const std::string &file)
    {
      put(files, file);
    }



    void
    unregister_file(const std::string &file)
    {
      take(files, file);
    }



    void
    add_child(const pid_t process_group)
    {
      for (auto &child : children)
        {
          pid_t free = 0;
          if (child.compare_exchange_strong(free, process_group))
            return;
        }
    }



    void
    remove_child(const pid_t process_group)
    {
      for (auto &child : children)
        {
          pid_t group = process_group;
          child.compare_exchange_strong(group, 0);
        }
    }
  } // namespace interruption
} // namespace knee_contact
