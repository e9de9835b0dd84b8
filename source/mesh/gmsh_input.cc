#include <knee_contact/base/external_program.h>
#include <knee_contact/base/input.h>
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/mesh/gmsh_input.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

namespace knee_contact
{
  namespace gmsh_input
  {
    namespace
    {
      bool
      is_number(const std::string &text)
      {
        return input::number(text).has_value();
      }



      // Run gmsh (argument vector, no shell, time limit) on @p input to
      // write @p msh; any failure, or an error in its log, is the run's
      // one-line error.
      void
      run_gmsh(const std::vector<std::string> &command,
               const std::string              &input,
               const std::string              &msh,
               const Limits                   &limits)
      {
        const std::string log =
          std::filesystem::path(msh).replace_extension(".log").string();
        const double        memory = limits.memory_bytes();
        const ProgramResult result =
          run_program(command, log, limits.seconds, memory);
        if (result.exit_code != 0 || !std::ifstream(msh).good() ||
            result.message.find("rror") != std::string::npos)
          throw std::runtime_error("Mesh/File: " +
                                   describe_failure(result,
                                                    "gmsh",
                                                    input,
                                                    "Mesh/Gmsh time limit",
                                                    limits.seconds,
                                                    "Mesh/Gmsh memory limit",
                                                    memory));
      }
    } // namespace



    double
    Limits::memory_bytes() const
    {
      if (megabytes > 0)
        return megabytes * 1048576.;
      // gmsh is a process of its own: the memory of the machine counts,
      // not this process's address space; at least the 256 MB it needs to
      // start and mesh small scenes (200 MB measured), at most the
      // address-space limit it would inherit. Under mpirun one gmsh runs
      // (on rank 0) for the ranks of this machine: the machine's share,
      // not one rank's.
      std::string  which;
      const double machine =
        memory::available(which, false) * parallel::ranks_on_this_machine();
      return std::min(std::max(machine / 4, 256 * 1048576.),
                      memory::address_space_limit());
    }



    std::vector<std::string>
    arguments(const std::string &text)
    {
      std::vector<std::string> words;
      std::istringstream       in(text);
      for (std::string w; in >> w;)
        words.push_back(w);
      const std::set<std::string> one_number = {
        "-clscale", "-clmin", "-clmax", "-clcurv", "-smooth"};
      const auto refuse = [&](const std::string &why) {
        throw std::runtime_error("Mesh/Gmsh arguments: " + why +
                                 " (allowed: -setnumber NAME NUMBER, "
                                 "-clscale, -clmin, -clmax, -clcurv, -smooth "
                                 "NUMBER)");
      };
      for (std::size_t i = 0; i < words.size();)
        if (words[i] == "-setnumber")
          {
            if (i + 2 >= words.size() || !is_number(words[i + 2]) ||
                words[i + 1].find_first_not_of(
                  "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                  "0123456789_.") != std::string::npos)
              refuse("-setnumber needs a name and a finite number");
            i += 3;
          }
        else if (one_number.count(words[i]) != 0)
          {
            if (i + 1 >= words.size() || !is_number(words[i + 1]))
              refuse(words[i] + " needs a finite number");
            i += 2;
          }
        else
          refuse("'" + words[i] + "' is not allowed");
      return words;
    }



    void
    check_geo(const std::string &file)
    {
      std::set<std::string> visited;
      // Recursion through Include, depth-limited against include cycles.
      const std::function<void(const std::string &, unsigned int)> check =
        [&](const std::string &name, const unsigned int depth) {
          const std::string canonical =
            std::filesystem::weakly_canonical(name).string();
          if (!visited.insert(canonical).second)
            return;
          if (depth > 16)
            throw std::runtime_error("Mesh/File: '" + file +
                                     "': Include nested deeper than 16");
          std::ifstream in(name);
          if (!in)
            throw std::runtime_error("Mesh/File: cannot open '" + name +
                                     "' (included by '" + file + "')");
          // A script, read whole: bounded (generated .geo files with
          // thousands of points take a few MB).
          constexpr std::uintmax_t max_size = 64u << 20;
          std::error_code          code;
          if (std::filesystem::file_size(name, code) > max_size && !code)
            throw std::runtime_error("Mesh/File: '" + name +
                                     "' is larger than " +
                                     std::to_string(max_size >> 20) +
                                     " MB, the most a .geo script may be");
          std::stringstream buffer;
          buffer << in.rdbuf();
          std::string text = buffer.str();
          // Blank out comments, keeping line breaks for the line numbers.
          for (std::size_t i = 0; i + 1 < text.size(); ++i)
            if (text[i] == '/' && text[i + 1] == '/')
              for (; i < text.size() && text[i] != '\n'; ++i)
                text[i] = ' ';
            else if (text[i] == '/' && text[i + 1] == '*')
              for (;
                   i < text.size() && !(text[i] == '*' && i + 1 < text.size() &&
                                        text[i + 1] == '/');
                   ++i)
                if (text[i] != '\n')
                  text[i] = ' ';
          static const std::set<std::string> forbidden = {
            "SystemCall",
            "NonBlockingSystemCall",
            "OnelabRun",
            "Merge",
            "MergeWithBoundingBox",
            "Save",
            "Print",
            "CreateDir",
            "DeleteFile",
            "RenameFile",
            "Plugin",
            "Shell"};
          unsigned int line = 1;
          for (std::size_t i = 0; i < text.size();)
            {
              const char c = text[i];
              if (c == '\n')
                {
                  ++line;
                  ++i;
                  continue;
                }
              if (!(std::isalpha(static_cast<unsigned char>(c)) || c == '_'))
                {
                  ++i;
                  continue;
                }
              std::size_t j = i;
              while (j < text.size() &&
                     (std::isalnum(static_cast<unsigned char>(text[j])) ||
                      text[j] == '_' || text[j] == '.'))
                ++j;
              const std::string word = text.substr(i, j - i);
              const std::size_t end  = text.find(';', j);
              const std::string statement =
                text.substr(j, end == std::string::npos ? end : end - j);
              const auto where =
                "Mesh/File: '" + name + "' line " + std::to_string(line) + ": ";
              if (forbidden.count(word) != 0 || word.rfind("Solver.", 0) == 0 ||
                  (word == "Printf" &&
                   statement.find('>') != std::string::npos))
                throw std::runtime_error(
                  where + "'" + word +
                  "' runs programs or writes files; knee_contact does not "
                  "run such a .geo (mesh it yourself and give the .msh)");
              if (word == "Include")
                {
                  const auto open  = statement.find('"');
                  const auto close = statement.find('"', open + 1);
                  if (open == std::string::npos || close == std::string::npos)
                    throw std::runtime_error(where +
                                             "Include without a file name");
                  const std::filesystem::path included =
                    statement.substr(open + 1, close - open - 1);
                  check(included.is_absolute()
                          ? included.string()
                          : (std::filesystem::path(name).parent_path() /
                             included)
                              .string(),
                        depth + 1);
                }
              i = j;
            }
        };
      check(file, 0);
    }



    void
    mesh(const std::string              &geo,
         const std::string              &msh,
         const std::vector<std::string> &extra,
         const Limits                   &limits)
    {
      check_geo(geo);
      // Format 4.1: its $Entities section lists every surface and volume, so
      // one without a physical group (whose cells GridIn would drop
      // silently) can be found by check_msh. -3 meshes the volumes of a 3D
      // geometry and is -2 for a 2D one.
      std::vector<std::string> command = {
        "gmsh", "-3", "-format", "msh41", "-v", "2", "-nopopup"};
      command.insert(command.end(), extra.begin(), extra.end());
      command.insert(command.end(), {"-o", msh, geo});
      run_gmsh(command, geo, msh, limits);
    }



    bool
    is_binary_msh(const std::string &file)
    {
      // The first two lines from the first bytes only: the file may be
      // anything, of any size.
      std::ifstream in(file, std::ios::binary);
      char          start[256];
      in.read(start, sizeof(start));
      std::istringstream lines(std::string(start, in.gcount()));
      std::string        header, format;
      std::getline(lines, header);
      std::getline(lines, format);
      std::istringstream words(format);
      std::string        version, file_type;
      words >> version >> file_type;
      return (header == "$MeshFormat" || header == "$MeshFormat\r") &&
             file_type == "1";
    }



    void
    convert(const std::string &binary_msh,
            const std::string &msh,
            const Limits      &limits)
    {
      // -0: read the file and write it out again, no meshing.
      run_gmsh({"gmsh",
                "-0",
                "-format",
                "msh41",
                "-v",
                "2",
                "-nopopup",
                "-o",
                msh,
                binary_msh},
               binary_msh,
               msh,
               limits);
    }
  } // namespace gmsh_input
} // namespace knee_contact
