#ifndef knee_contact_scene_file_h
#define knee_contact_scene_file_h

#include <set>
#include <string>

namespace knee_contact
{
  /**
   * What ParameterHandler lets pass and a scene must not: the same `set`
   * twice in one subsection (the last one would win silently), and numbered
   * subsections ('Material 2', 'Condition 0', 'Interface 1') missing or
   * beyond their count (a missing one would silently take the defaults).
   * ParameterHandler has no hook for either, so the file is read here once
   * more, as text (.prm) or JSON (.json, with nlohmann-json's parser).
   */
  class SceneOutline
  {
  public:
    /**
     * Read @p scene_file; throws a one-line error naming the file, line and
     * parameter of a repeated `set` or a repeated JSON key, and refuses a
     * file beyond the limits that bound what parsing it costs: 16 MB, and
     * subsections (JSON objects and arrays) nested 16 levels deep.
     */
    explicit SceneOutline(const std::string &scene_file);

    /**
     * Require subsections '@p prefix 0' ... '@p prefix n-1' inside
     * @p section (e.g. "Materials", "Material", n) and no other
     * '@p prefix k'; the error names the file and the count parameter
     * @p count_parameter.
     */
    void
    check_numbered(const std::string &section,
                   const std::string &prefix,
                   const unsigned int n,
                   const std::string &count_parameter) const;

  private:
    std::string file;
    /** Every subsection path in the file, e.g. "Materials/Material 0". */
    std::set<std::string> subsections;
  };
} // namespace knee_contact

#endif
