#include <knee_contact/base/scene_file.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace knee_contact
{
  namespace
  {
    // Trim and collapse runs of white space, as ParameterHandler compares
    // names.
    std::string
    normalise(const std::string &text)
    {
      std::istringstream words(text);
      std::string        result;
      for (std::string w; words >> w;)
        result += (result.empty() ? "" : " ") + w;
      return result;
    }

    std::string
    join(const std::vector<std::string> &path)
    {
      std::string result;
      for (const auto &p : path)
        result += (result.empty() ? "" : "/") + p;
      return result;
    }
  } // namespace



  SceneOutline::SceneOutline(const std::string &scene_file)
    : file(scene_file)
  {
    std::ifstream in(scene_file);
    if (!in)
      throw std::runtime_error("cannot open scene file '" + scene_file + "'");
    // Limits of a scene file, far beyond any scene (the examples nest three
    // levels deep and take a few kB), that bound what a hostile file costs:
    // deal.II's ParameterHandler and Boost's JSON reader take time and
    // memory that grow with the square of the nesting and recurse on the
    // stack (30 000 levels: 15 s and 1.1 GB).
    constexpr unsigned int   max_depth = 16;
    constexpr std::uintmax_t max_size  = 16u << 20;
    std::error_code          code;
    const std::uintmax_t size = std::filesystem::file_size(scene_file, code);
    if (!code && size > max_size)
      throw std::runtime_error(
        scene_file + ": " + std::to_string(size >> 20) +
        " MB; a scene file is at most " + std::to_string(max_size >> 20) +
        " MB (meshes and data go in files of their own)");
    const auto too_deep = [&](const std::string &where) {
      return std::runtime_error(
        scene_file + where + ": subsections nested deeper than " +
        std::to_string(max_depth) + " levels (scenes need 3)");
    };

    if (std::filesystem::path(scene_file).extension() == ".json")
      {
        // A stack of the keys seen in each open object.
        std::vector<std::string>           path;
        std::vector<std::set<std::string>> keys(1);
        std::vector<bool>                  named;
        std::string                        pending_key;
        const auto                         callback = [&](int                              depth,
                                  nlohmann::json::parse_event_t    event,
                                  [[maybe_unused]] nlohmann::json &value) {
          using event_t = nlohmann::json::parse_event_t;
          if (depth > int(max_depth))
            throw too_deep("");
          if (event == event_t::key)
            {
              const std::string key = normalise(value.get<std::string>());
              if (!keys.back().insert(key).second)
                throw std::runtime_error(
                  scene_file + ": '" + key + "' appears twice in '" +
                  (path.empty() ? std::string("the top level") : join(path)) +
                  "'");
              pending_key = key;
            }
          else if (event == event_t::object_start)
            {
              named.push_back(!pending_key.empty());
              if (named.back())
                {
                  path.push_back(pending_key);
                  subsections.insert(join(path));
                }
              keys.emplace_back();
              pending_key.clear();
            }
          else if (event == event_t::object_end)
            {
              if (keys.size() > 1)
                keys.pop_back();
              if (!named.empty())
                {
                  if (named.back() && !path.empty())
                    path.pop_back();
                  named.pop_back();
                }
            }
          else if (event == event_t::value)
            pending_key.clear();
          return true;
        };
        // Syntax errors are ParameterHandler's to report, with its message.
        try
          {
            [[maybe_unused]] const auto outline =
              nlohmann::json::parse(in, callback);
          }
        catch (const nlohmann::json::exception &)
          {}
        return;
      }

    std::vector<std::string>                          path;
    std::map<std::string, std::map<std::string, int>> set_lines;
    std::string                                       line, statement;
    int                                               number = 0, first = 0;
    while (std::getline(in, line))
      {
        ++number;
        const auto hash = line.find('#');
        if (hash != std::string::npos)
          line.erase(hash);
        // A trailing backslash continues the statement on the next line.
        const std::string trimmed = normalise(line);
        if (statement.empty())
          first = number;
        if (!trimmed.empty() && trimmed.back() == '\\')
          {
            statement += trimmed.substr(0, trimmed.size() - 1) + " ";
            continue;
          }
        statement = normalise(statement + trimmed);
        if (statement.rfind("subsection ", 0) == 0)
          {
            if (path.size() == max_depth)
              throw too_deep(":" + std::to_string(first));
            path.push_back(normalise(statement.substr(11)));
            subsections.insert(join(path));
          }
        else if (statement == "end")
          {
            if (!path.empty())
              path.pop_back();
          }
        else if (statement.rfind("set ", 0) == 0)
          {
            const auto        equal = statement.find('=');
            const std::string name  = normalise(statement.substr(4, equal - 4));
            const std::string where = join(path);
            const auto [it, fresh]  = set_lines[where].emplace(name, first);
            if (!fresh)
              throw std::runtime_error(
                scene_file + ":" + std::to_string(first) + ": '" + name +
                "' is set twice in subsection '" + where + "' (first on line " +
                std::to_string(it->second) + "); the last would win silently");
          }
        statement.clear();
      }
  }



  void
  SceneOutline::check_numbered(const std::string &section,
                               const std::string &prefix,
                               const unsigned int n,
                               const std::string &count_parameter) const
  {
    for (unsigned int k = 0; k < n; ++k)
      if (subsections.count(section + "/" + prefix + " " + std::to_string(k)) ==
          0)
        throw std::runtime_error(
          file + ": " + section + "/" + count_parameter + " is " +
          std::to_string(n) + " but there is no subsection '" + prefix + " " +
          std::to_string(k) + "' (it would silently take the defaults)");
    const std::string start = section + "/" + prefix + " ";
    for (const auto &s : subsections)
      if (s.rfind(start, 0) == 0 &&
          s.find('/', start.size()) == std::string::npos)
        {
          const std::string index = s.substr(start.size());
          if (index.find_first_not_of("0123456789") != std::string::npos ||
              index.empty() || index.size() > 6 || std::stoul(index) >= n)
            throw std::runtime_error(
              file + ": subsection '" + s + "' is beyond " + section + "/" +
              count_parameter + " = " + std::to_string(n) +
              " (subsections count from 0)");
        }
  }
} // namespace knee_contact
