#ifndef knee_contact_mesh_readers_line_reader_h
#define knee_contact_mesh_readers_line_reader_h

#include <knee_contact/base/input.h>
#include <knee_contact/mesh/mesh_readers.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace knee_contact
{
  namespace mesh_readers
  {
    /**
     * What the hand-written readers (Abaqus, UCD, VTK, VTU) share: one line
     * reader whose errors name file and line, the field and number parsers,
     * and the step from a ring of vertices to deal.II's cell.
     */
    namespace internal
    {
      /** The longest line a text mesh file may have (Abaqus allows 256). */
      constexpr std::size_t max_line_length = 1 << 20;

      enum class LineRead
      {
        line,
        end,
        too_long
      };

      /**
       * The next line of @p in into @p line (without its '\n'), reading at
       * most max_line_length characters through @p buffer: a file of one
       * endless line (a sparse file of zeros) is never read into memory.
       */
      inline LineRead
      read_line(std::istream &in, std::vector<char> &buffer, std::string &line)
      {
        buffer.resize(max_line_length + 1);
        in.getline(buffer.data(), buffer.size());
        const std::streamsize n = in.gcount();
        if (in.bad() || (n == 0 && in.eof()))
          return LineRead::end;
        if (in.fail() && !in.eof())
          return LineRead::too_long;
        // gcount() counts the '\n' it took, not at the end of the file.
        line.assign(buffer.data(), in.eof() ? n : n - 1);
        return LineRead::line;
      }



      /**
       * A file mapped read-only into memory (mmap): the whole file is
       * addressable without being read or allocated; pages are read when
       * touched, so a huge or sparse file costs nothing until its content
       * is used, and each size a reader takes from the file is checked
       * before anything of that size is allocated. Written by hand because
       * neither deal.II nor the C++ library maps files.
       */
      class MappedFile
      {
      public:
        explicit MappedFile(const std::string &file)
        {
          const int fd = open(file.c_str(), O_RDONLY | O_CLOEXEC);
          AssertThrow(fd >= 0,
                      ExcMessage("Mesh/File: cannot open '" + file + "'"));
          struct stat status;
          if (fstat(fd, &status) == 0 && status.st_size > 0)
            {
              size = static_cast<std::size_t>(status.st_size);
              data = mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
            }
          close(fd);
          AssertThrow(data != MAP_FAILED,
                      ExcMessage("Mesh/File: cannot read '" + file + "'"));
        }

        ~MappedFile()
        {
          if (data != MAP_FAILED && data != nullptr)
            munmap(data, size);
        }

        MappedFile(const MappedFile &) = delete;
        MappedFile &
        operator=(const MappedFile &) = delete;

        std::string_view
        text() const
        {
          return data == nullptr
                   ? std::string_view()
                   : std::string_view(static_cast<const char *>(data), size);
        }

      private:
        void       *data = nullptr;
        std::size_t size = 0;
      };



      /**
       * A text file read line by line, with errors that name file and line.
       */
      class Lines
      {
      public:
        explicit Lines(const std::string &file)
          : file(file)
          , in(file)
        {
          AssertThrow(in.good(),
                      ExcMessage("Mesh/File: cannot open '" + file + "'"));
          size = std::filesystem::file_size(file);
        }

        bool
        next(std::string &line)
        {
          if (pending)
            {
              line    = held;
              pending = false;
              return true;
            }
          const LineRead read = read_line(in, buffer, line);
          if (read == LineRead::end)
            return false;
          if (read == LineRead::too_long)
            {
              ++number;
              fail("a line longer than " +
                   std::to_string(max_line_length / 1024) +
                   " kB (no mesh format read by lines needs that; not a "
                   "text mesh file?)");
            }
          ++number;
          if (!line.empty() && line.back() == '\r')
            line.pop_back();
          return true;
        }

        /** Give @p line back: the next call of next() returns it again. */
        void
        put_back(const std::string &line)
        {
          held    = line;
          pending = true;
        }

        [[noreturn]] void
        fail(const std::string &what) const
        {
          throw std::runtime_error(
            input::cap("Mesh/File: '" + file + "' line " +
                       std::to_string(number) + ": " + what));
        }

        const std::string file;
        std::uintmax_t    size   = 0;
        unsigned long     number = 0;

      private:
        std::ifstream     in;
        std::vector<char> buffer;
        std::string       held;
        bool              pending = false;
      };

      inline std::string
      upper(std::string text)
      {
        for (char &c : text)
          c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        return text;
      }

      inline std::string
      trim(const std::string &text)
      {
        const auto first = text.find_first_not_of(" \t");
        if (first == std::string::npos)
          return "";
        return text.substr(first, text.find_last_not_of(" \t") - first + 1);
      }

      /** The white-space separated words of @p line. */
      inline std::vector<std::string>
      words(const std::string &line)
      {
        std::vector<std::string> result;
        std::istringstream       stream(line);
        for (std::string word; stream >> word;)
          result.push_back(word);
        return result;
      }

      inline std::vector<std::string>
      fields(const std::string &line)
      {
        std::vector<std::string> result;
        std::stringstream        stream(line);
        std::string              field;
        while (std::getline(stream, field, ','))
          result.push_back(trim(field));
        // "1, 2," has no third field.
        if (!result.empty() && result.back().empty())
          result.pop_back();
        return result;
      }

      inline long long
      to_integer(const std::string &text, const Lines &lines)
      {
        std::size_t end   = 0;
        long long   value = 0;
        try
          {
            value = std::stoll(text, &end);
          }
        catch (...)
          {
            end = 0;
          }
        if (end == 0 || end != text.size())
          lines.fail("'" + text + "' is not an integer");
        return value;
      }

      inline double
      to_number(const std::string &text, const Lines &lines)
      {
        const auto value = input::number(text);
        if (!value)
          lines.fail("'" + text + "' is not a finite number");
        return *value;
      }

      /**
       * The value of "KEY=value" among the options of a keyword line, upper
       * case, or "" if absent.
       */
      inline std::string
      option(const std::vector<std::string> &keyword_fields,
             const std::string              &key)
      {
        for (std::size_t i = 1; i < keyword_fields.size(); ++i)
          {
            const auto equal = keyword_fields[i].find('=');
            if (equal != std::string::npos &&
                upper(trim(keyword_fields[i].substr(0, equal))) == key)
              return upper(trim(keyword_fields[i].substr(equal + 1)));
          }
        return "";
      }

      inline bool
      has_flag(const std::vector<std::string> &keyword_fields,
               const std::string              &flag)
      {
        for (std::size_t i = 1; i < keyword_fields.size(); ++i)
          if (upper(keyword_fields[i]) == flag)
            return true;
        return false;
      }

      /**
       * Add a cell whose @p vertices are listed as Abaqus, UCD and VTK list
       * them: round a triangle or quadrilateral, a tetrahedron as it is,
       * a hexahedron's bottom then top face each round it. deal.II's order
       * is lexicographic (0 1 3 2 round a quadrilateral, 0 1 3 2 4 5 7 6
       * for a hexahedron).
       */
      template <int dim>
      void
      add_cell(Description<dim>         &mesh,
               std::vector<unsigned int> vertices,
               const types::material_id  material_id)
      {
        if (vertices.size() == 8)
          vertices = {vertices[0],
                      vertices[1],
                      vertices[3],
                      vertices[2],
                      vertices[4],
                      vertices[5],
                      vertices[7],
                      vertices[6]};
        else if (dim == 2 && vertices.size() == 4)
          std::swap(vertices[2], vertices[3]);
        CellData<dim> cell(vertices.size());
        cell.vertices    = vertices;
        cell.material_id = material_id;
        mesh.cells.push_back(cell);
      }

      inline void
      add_boundary_line(Description<2>          &mesh,
                        const unsigned int       a,
                        const unsigned int       b,
                        const types::boundary_id boundary_id)
      {
        CellData<1> line;
        line.vertices    = {a, b};
        line.boundary_id = boundary_id;
        mesh.subcells.boundary_lines.push_back(line);
      }

      /**
       * A boundary triangle or quadrilateral of a 3D mesh whose @p vertices
       * run round it.
       */
      inline void
      add_boundary_face(Description<3>           &mesh,
                        std::vector<unsigned int> vertices,
                        const types::boundary_id  boundary_id)
      {
        if (vertices.size() == 4)
          std::swap(vertices[2], vertices[3]);
        CellData<2> face(vertices.size());
        face.vertices    = vertices;
        face.boundary_id = boundary_id;
        mesh.subcells.boundary_quads.push_back(face);
      }

      /**
       * The names of the cell field that gives material ids (and boundary
       * ids of line cells) in VTK files, in the order they are looked for:
       * knee_contact's and deal.II's MaterialID, then what meshio writes for
       * a Gmsh mesh (gmsh:physical), VTK's own readers of Exodus and Gmsh
       * files (CellEntityIds) and meshio for Medit files (medit:ref).
       */
      inline const std::vector<std::string> &
      id_field_names()
      {
        static const std::vector<std::string> names = {"MaterialID",
                                                       "gmsh:physical",
                                                       "CellEntityIds",
                                                       "medit:ref"};
        return names;
      }

      /**
       * The 2D mesh of a VTK unstructured grid, read by the .vtu and .vtk
       * readers: @p points (x, y, z each; z must be 0), per cell the end
       * of its vertices in @p connectivity (@p offsets) and its VTK type
       * (@p types: vertex 1, ignored; line 3, a boundary edge; triangle 5;
       * quadrilateral 9), and the cell field @p ids (empty: all 0), named
       * @p id_name in messages. @p fail throws.
       */
      Description<2>
      unstructured_grid(const std::vector<double> &points,
                        const std::vector<double> &offsets,
                        const std::vector<double> &connectivity,
                        const std::vector<double> &types,
                        const std::vector<double> &ids,
                        const std::string         &id_name,
                        const std::function<void(const std::string &)> &fail);
    } // namespace internal
  }   // namespace mesh_readers
} // namespace knee_contact

#endif
