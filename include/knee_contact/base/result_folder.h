#ifndef knee_contact_result_folder_h
#define knee_contact_result_folder_h

#include <string>

namespace knee_contact
{
  /**
   * All or nothing: a run writes its result set into a fresh, uniquely named
   * folder beside the output folder ('.<name>.new-XXXXXX') and swaps it in
   * at the end with one atomic rename (renameat2 RENAME_EXCHANGE), so the
   * output folder always holds either the previous complete set or the new
   * complete set, never a mix and never files of an earlier run. A lock
   * ('.<name>.lock' beside the folder, flock) refuses a second run on the
   * same folder while the first one lives. A run that fails or is
   * interrupted leaves the folder untouched (see interruption.h).
   *
   * Written by hand because neither deal.II nor the standard library
   * offers an atomic exchange of folders.
   */
  class ResultFolder
  {
  public:
    /**
     * Lock @p folder (throws a one-line error naming Output/Folder if
     * another run holds it, or if it cannot be created) and create the
     * staging folder beside it.
     */
    explicit ResultFolder(const std::string &folder);

    /** Removes the staging folder unless committed; releases the lock. */
    ~ResultFolder();

    ResultFolder(const ResultFolder &) = delete;
    ResultFolder &
    operator=(const ResultFolder &) = delete;

    /** Where the files of this run go until commit(). */
    const std::string &
    staging() const
    {
      return staging_folder;
    }

    /** The output folder of the scene. */
    const std::string &
    final() const
    {
      return folder;
    }

    /**
     * Swap the staging folder in for the output folder and remove the
     * previous result set.
     */
    void
    commit();

  private:
    std::string folder;
    std::string staging_folder;
    std::string lock_file;
    int         lock_descriptor = -1;
    bool        committed       = false;
  };
} // namespace knee_contact

#endif
