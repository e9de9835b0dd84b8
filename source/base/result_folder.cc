#include <knee_contact/base/interruption.h>
#include <knee_contact/base/result_folder.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace knee_contact
{
  namespace
  {
    namespace fs = std::filesystem;

    // The marker of a result set: only a folder that holds one (or the
    // summary.json of an earlier version, or nothing) is ever replaced, so
    // a mistyped Output/Folder can never delete a researcher's files.
    const char marker[] = ".knee_contact_results";

    std::runtime_error
    error(const std::string &message)
    {
      return std::runtime_error("Output/Folder: " + message);
    }

    bool
    is_result_set(const fs::path &folder)
    {
      std::error_code code;
      if (fs::exists(folder / marker, code) ||
          fs::exists(folder / "summary.json", code))
        return true;
      return fs::is_empty(folder, code) && !code;
    }
  } // namespace



  ResultFolder::ResultFolder(const std::string &folder_name)
  {
    // @p p normalised, without a trailing '/'; whether it names a folder
    // of its own (not '.', '..' or '/').
    const auto normal = [](const fs::path &p) {
      fs::path result = p.lexically_normal();
      if (!result.has_filename() && result.has_parent_path())
        result = result.parent_path();
      return result;
    };
    const auto own_name = [](const fs::path &p) {
      return !p.filename().empty() && p.filename() != "." &&
             p.filename() != "..";
    };
    fs::path path = normal(folder_name);
    if (!own_name(path))
      throw error("'" + folder_name +
                  "' must name a folder of its own (not '.', '..' or '/')");
    // A symbolic link (results -> /data/run7) stays a link: the result set
    // is swapped in at its target, beside which staging and lock live, so
    // two runs through different names still lock the same folder.
    std::error_code code;
    for (unsigned int hops = 0; fs::is_symlink(fs::symlink_status(path, code));
         ++hops)
      {
        if (hops == 40)
          throw error("'" + folder_name +
                      "' is a symbolic link that leads round in a circle");
        const fs::path target = fs::read_symlink(path, code);
        if (code)
          throw error("cannot read the link '" + path.string() +
                      "': " + code.message());
        path =
          normal(target.is_absolute() ? target : path.parent_path() / target);
        if (!own_name(path))
          throw error("'" + folder_name + "' links to '" + path.string() +
                      "', which does not name a folder of its own");
      }
    folder                 = path.string();
    const std::string name = path.filename().string();
    const fs::path parent  = path.has_parent_path() ? path.parent_path() : ".";

    fs::create_directories(parent, code);
    if (code)
      throw error("cannot create '" + parent.string() + "': " + code.message());
    if (fs::exists(path, code) && !fs::is_directory(path, code))
      throw error("'" + folder + "' exists and is not a folder");
    if (fs::is_directory(path, code) && !is_result_set(path))
      throw error("'" + folder +
                  "' holds files that are not a knee_contact result set; "
                  "choose a new or empty folder (it would be replaced)");
    // A folder without write permission is one the user protected (and
    // the previous set could not be removed after the swap): refused, for
    // root too, who would pass access(W_OK).
    struct stat status;
    if (stat(folder.c_str(), &status) == 0 && S_ISDIR(status.st_mode) &&
        ((status.st_mode & 0222) == 0 || access(folder.c_str(), W_OK) != 0))
      throw error("'" + folder +
                  "' is read-only; make it writable (chmod u+w) to replace "
                  "its results, or choose another folder");

    // One run per folder. flock dies with the process, so a killed run
    // never blocks the next one; the inode check catches a lock file that
    // another run removed between our open and our flock.
    lock_file = (parent / ("." + name + ".lock")).string();
    for (unsigned int attempt = 0; attempt < 2; ++attempt)
      {
        lock_descriptor =
          open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (lock_descriptor < 0)
          throw error("cannot write beside '" + folder + "' (in '" +
                      parent.string() + "'): " + std::strerror(errno));
        if (flock(lock_descriptor, LOCK_EX | LOCK_NB) != 0)
          {
            close(lock_descriptor);
            lock_descriptor = -1;
            throw error("another knee_contact run is writing '" + folder +
                        "'; wait for it to finish or choose another folder");
          }
        struct stat held, on_disk;
        if (fstat(lock_descriptor, &held) == 0 &&
            stat(lock_file.c_str(), &on_disk) == 0 &&
            held.st_ino == on_disk.st_ino && held.st_dev == on_disk.st_dev)
          break;
        close(lock_descriptor);
        lock_descriptor = -1;
      }
    if (lock_descriptor < 0)
      throw error("cannot lock '" + lock_file + "'");
    interruption::register_file(lock_file);

    std::string staging = (parent / ("." + name + ".new-XXXXXX")).string();
    if (mkdtemp(staging.data()) == nullptr)
      {
        const std::string reason = std::strerror(errno);
        interruption::unregister_file(lock_file);
        unlink(lock_file.c_str());
        close(lock_descriptor);
        throw error("cannot create a folder beside '" + folder +
                    "': " + reason);
      }
    staging_folder = staging;
    interruption::register_folder(staging_folder);
    // mkdtemp makes the folder private (0700); a result set is as readable
    // as any folder the user creates.
    const mode_t mask = umask(0);
    umask(mask);
    chmod(staging_folder.c_str(), 0777 & ~mask);
    std::FILE *const mark = std::fopen((staging + "/" + marker).c_str(), "w");
    if (mark != nullptr)
      std::fclose(mark);
  }



  ResultFolder::~ResultFolder()
  {
    std::error_code code;
    if (!committed)
      fs::remove_all(staging_folder, code);
    interruption::unregister_folder(staging_folder);
    interruption::unregister_file(lock_file);
    unlink(lock_file.c_str());
    close(lock_descriptor);
  }



  void
  ResultFolder::commit()
  {
    std::error_code code;
    if (!fs::exists(folder, code))
      {
        if (std::rename(staging_folder.c_str(), folder.c_str()) != 0)
          throw error("cannot rename '" + staging_folder + "' to '" + folder +
                      "': " + std::strerror(errno));
        interruption::results_written();
        committed = true;
        return;
      }
    // One atomic exchange: afterwards the staging name holds the previous
    // set, which is removed.
    if (renameat2(AT_FDCWD,
                  staging_folder.c_str(),
                  AT_FDCWD,
                  folder.c_str(),
                  RENAME_EXCHANGE) != 0)
      {
        // File systems without RENAME_EXCHANGE: two renames; between them
        // the folder is briefly absent, never mixed.
        const std::string previous = staging_folder + ".previous";
        if (std::rename(folder.c_str(), previous.c_str()) != 0 ||
            std::rename(staging_folder.c_str(), folder.c_str()) != 0)
          throw error("cannot replace '" + folder +
                      "': " + std::strerror(errno));
        interruption::results_written();
        fs::remove_all(previous, code);
        committed = true;
        return;
      }
    interruption::results_written();
    fs::remove_all(staging_folder, code);
    committed = true;
  }
} // namespace knee_contact
