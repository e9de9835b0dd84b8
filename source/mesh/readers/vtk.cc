#include <knee_contact/base/memory.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>

// The legacy VTK format (.vtk), written by hand: deal.II 9.4's
// GridIn::read_vtk reads ASCII files of the 4.2 layout only and trusts their
// counts, while VTK 9, ParaView 5.10 and meshio write the 5.1 layout
// (CELLS as OFFSETS and CONNECTIVITY arrays) and meshio writes binary by
// default.
namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

    namespace
    {
      /**
       * A legacy VTK file in memory: keyword lines are text, data are
       * whitespace separated numbers (ASCII) or big-endian values right after
       * the keyword line (BINARY). Errors name the file and line.
       */
      class LegacyFile
      {
      public:
        explicit LegacyFile(const std::string &file)
          : file(file)
          , mapped(file)
          , text(mapped.text())
        {}

        [[noreturn]] void
        fail(const std::string &what) const
        {
          throw std::runtime_error(input::cap(where(what)));
        }

        /** "Mesh/File: 'f.vtk' line 12: @p what". */
        std::string
        where(const std::string &what) const
        {
          return "Mesh/File: '" + file + "' line " +
                 std::to_string(line_number) + ": " + what;
        }

        /** The next line, without its end; false at the end of the file. */
        bool
        line(std::string &result)
        {
          if (at >= text.size())
            return false;
          // Looked for within max_line_length only: the rest of a huge file
          // is not touched.
          const auto length = text.substr(at, max_line_length + 1).find('\n');
          const auto end    = length == std::string::npos
                                ? std::min(at + max_line_length + 1, text.size())
                                : at + length;
          line_number       = newlines + 1;
          if (end - at > max_line_length)
            fail("a line longer than " +
                 std::to_string(max_line_length / 1024) +
                 " kB where a keyword should be (not a VTK file?)");
          result = std::string(text.substr(at, end - at));
          if (!result.empty() && result.back() == '\r')
            result.pop_back();
          if (end < text.size())
            ++newlines;
          at = std::min(end + 1, text.size());
          return true;
        }

        /** The next line that is not blank, split into words. */
        std::vector<std::string>
        keyword_line(const std::string &what)
        {
          std::string text_line;
          while (line(text_line))
            {
              auto result = words(text_line);
              if (!result.empty())
                return result;
            }
          fail("the file ends where " + what + " should be");
        }

        /**
         * Whether the next word (after white space) is @p word, without
         * reading it.
         */
        bool
        next_is(const std::string &word) const
        {
          std::size_t p = at;
          while (p < text.size() &&
                 std::isspace(static_cast<unsigned char>(text[p])))
            ++p;
          if (p >= text.size())
            return false;
          return upper(std::string(text.substr(p, word.size()))) == word &&
                 (p + word.size() == text.size() ||
                  std::isspace(
                    static_cast<unsigned char>(text[p + word.size()])));
        }

        /** Skip white space; true at the end of the file. */
        bool
        at_end()
        {
          while (at < text.size() &&
                 std::isspace(static_cast<unsigned char>(text[at])))
            {
              if (text[at] == '\n')
                ++newlines;
              ++at;
            }
          return at >= text.size();
        }

        /**
         * A count from a keyword line: a non-negative integer no larger than
         * the file's size (each value takes at least a byte), so that
         * nothing is allocated for a count the file cannot hold.
         */
        std::size_t
        count(const std::string &word, const std::string &what) const
        {
          std::size_t end   = 0;
          long long   value = -1;
          try
            {
              value = std::stoll(word, &end);
            }
          catch (...)
            {
              end = 0;
            }
          if (end == 0 || end != word.size() || value < 0)
            fail(what + " '" + word + "' is not a count");
          if (static_cast<std::uintmax_t>(value) > text.size())
            fail(what + " " + word + " is more than the file's " +
                 std::to_string(text.size()) + " bytes can hold");
          return static_cast<std::size_t>(value);
        }

        /**
         * @p n values of the VTK data type @p type, as doubles (ids and
         * counts are integers far below 2^53); an array that is not @p keep
         * is read past (checked, not stored). The doubles are allocated
         * only if the memory available holds them.
         */
        std::vector<double>
        values(const std::size_t  n,
               const std::string &type,
               const std::string &section,
               const bool         keep = true)
        {
          // Bytes per value in BINARY files; "long" is 8 bytes as VTK and
          // meshio write it on 64-bit Linux.
          static const std::map<std::string, unsigned int> sizes = {
            {"unsigned_char", 1},
            {"char", 1},
            {"unsigned_short", 2},
            {"short", 2},
            {"unsigned_int", 4},
            {"int", 4},
            {"vtktypeint32", 4},
            {"vtktypeuint32", 4},
            {"unsigned_long", 8},
            {"long", 8},
            {"vtktypeint64", 8},
            {"vtktypeuint64", 8},
            {"float", 4},
            {"double", 8}};
          const auto size = sizes.find(type);
          if (size == sizes.end())
            fail("data type '" + type +
                 "' (knee_contact reads char, short, int, long, their "
                 "unsigned kinds, vtktypeint32/64, float and double)");
          std::vector<double> result;
          const auto          allocate = [&]() {
            if (!keep)
              return;
            std::string  limit;
            const double available = memory::available(limit);
            if (8. * n > 0.8 * available)
              fail(section + ": " + std::to_string(n) + " values need " +
                   memory::megabytes(8. * n) + "; " +
                   memory::megabytes(available) + " are available (" + limit +
                   ")");
            result.reserve(n);
          };
          if (binary)
            {
              const std::size_t bytes = size->second;
              if (n > (text.size() - at) / bytes)
                fail(section + ": " + std::to_string(n) + " values of type " +
                     type + " are more than the rest of the file holds");
              allocate();
              if (keep)
                {
                  const Kind kind = kind_of(type);
                  for (std::size_t i = 0; i < n; ++i)
                    result.push_back(
                      binary_value(text.data() + at + i * bytes, kind, bytes));
                }
              at += n * bytes;
            }
          else
            {
              if (n > text.size() - at)
                fail(section + ": " + std::to_string(n) +
                     " values are more than the rest of the file holds");
              allocate();
              for (std::size_t i = 0; i < n; ++i)
                {
                  const std::string word = ascii_word();
                  if (word.empty())
                    fail("the file ends inside " + section + " (value " +
                         std::to_string(i + 1) + " of " + std::to_string(n) +
                         ")");
                  const auto value = input::number(word);
                  if (!value)
                    fail("'" + word + "' is not a finite number");
                  if (keep)
                    result.push_back(*value);
                }
            }
          return result;
        }

        /**
         * Skip VTK 9's METADATA block after an array (component names and
         * information keys), which ends at a blank line.
         */
        void
        skip_metadata()
        {
          // Binary data end with a newline that is not white space of a
          // line (it may be the first byte of nothing else).
          if (binary && at < text.size() && text[at] == '\n')
            {
              ++at;
              ++newlines;
            }
          if (!next_is("METADATA"))
            return;
          std::string next;
          while (line(next) && trim(next).empty())
            ;
          // METADATA itself, then its lines up to a blank one.
          while (line(next) && !trim(next).empty())
            ;
        }

        const std::string file;

      private:
        // Declared before text, which views it.
        MappedFile mapped;

      public:
        bool binary = false;
        /** The longest ASCII value read. */
        static constexpr std::size_t max_word_length = 256;
        /** The line of what was read last, for messages. */
        unsigned long line_number = 0;

      private:
        std::string
        ascii_word()
        {
          at_end();
          if (at < text.size())
            line_number = newlines + 1;
          const std::size_t start = at;
          while (at < text.size() &&
                 !std::isspace(static_cast<unsigned char>(text[at])))
            if (++at - start > max_word_length)
              fail("a word of more than " + std::to_string(max_word_length) +
                   " characters where a number should be");
          return std::string(text.substr(start, at - start));
        }

        enum class Kind
        {
          floating,
          double_precision,
          signed_integer,
          unsigned_integer
        };

        static Kind
        kind_of(const std::string &type)
        {
          if (type == "float")
            return Kind::floating;
          if (type == "double")
            return Kind::double_precision;
          return type == "char" || type == "short" || type == "int" ||
                     type == "long" || type == "vtktypeint32" ||
                     type == "vtktypeint64"
                   ? Kind::signed_integer
                   : Kind::unsigned_integer;
        }

        static double
        binary_value(const char        *data,
                     const Kind         kind,
                     const unsigned int bytes)
        {
          // Big-endian, as the format defines.
          std::uint64_t bits = 0;
          for (unsigned int b = 0; b < bytes; ++b)
            bits = (bits << 8) | static_cast<unsigned char>(data[b]);
          if (kind == Kind::floating)
            {
              const auto u = static_cast<std::uint32_t>(bits);
              float      f;
              std::memcpy(&f, &u, 4);
              return f;
            }
          if (kind == Kind::double_precision)
            {
              double d;
              std::memcpy(&d, &bits, 8);
              return d;
            }
          const bool is_signed = kind == Kind::signed_integer;
          if (is_signed && bytes < 8 && (bits >> (8 * bytes - 1)) != 0)
            return static_cast<double>(static_cast<std::int64_t>(bits) -
                                       (std::int64_t(1) << (8 * bytes)));
          if (is_signed)
            return static_cast<double>(static_cast<std::int64_t>(bits));
          return static_cast<double>(bits);
        }

        std::string_view text;
        std::size_t      at = 0;
        /** Line ends before at (binary data are not counted). */
        unsigned long newlines = 0;
      };



      /**
       * Read the arrays of the FIELD whose keyword line is @p words, each of
       * @p n tuples (any number if @p n is std::size_t(-1): a field of the
       * whole data set), and give each that is @p wanted (by name) to
       * @p keep (name, components, values); without @p keep none is kept.
       */
      void
      read_field(LegacyFile                                        &vtk,
                 const std::vector<std::string>                    &words,
                 const std::size_t                                  n,
                 const std::function<void(const std::string &,
                                          const unsigned int,
                                          std::vector<double> &&)> &keep,
                 const std::function<bool(const std::string &)>    &wanted)
      {
        if (words.size() < 3)
          vtk.fail("FIELD needs a name and an array count");
        const std::size_t n_arrays = vtk.count(words[2], "FIELD array count");
        for (std::size_t a = 0; a < n_arrays; ++a)
          {
            const auto array = vtk.keyword_line("a FIELD array");
            if (array.size() < 4)
              vtk.fail("a FIELD array needs a name, components, tuples and "
                       "a data type");
            const std::size_t n_components =
              vtk.count(array[1], "component count");
            const std::size_t n_tuples = vtk.count(array[2], "tuple count");
            if (n != std::size_t(-1) && n_tuples != n)
              vtk.fail("FIELD array '" + array[0] + "' has " + array[2] +
                       " tuples, its section " + std::to_string(n));
            if (n_components < 1 ||
                (n_tuples > 0 && n_components > std::size_t(-1) / n_tuples))
              vtk.fail("FIELD array '" + array[0] + "' has " + array[1] +
                       " components");
            // Arrays nobody keeps are read past, not stored.
            const bool kept   = keep != nullptr && wanted(array[0]);
            auto       values = vtk.values(n_components * n_tuples,
                                     array[3],
                                     "FIELD array " + array[0],
                                     kept);
            if (kept)
              keep(array[0],
                   static_cast<unsigned int>(n_components),
                   std::move(values));
            vtk.skip_metadata();
          }
      }



      /**
       * Read the attributes of a CELL_DATA or POINT_DATA section of @p n
       * tuples until the next section; keep the cell field named in
       * id_field_names() that comes first in that list in @p ids.
       */
      void
      read_attributes(LegacyFile               &vtk,
                      const std::size_t         n,
                      const bool                cells,
                      std::vector<double>      &ids,
                      std::string              &id_name,
                      std::vector<std::string> &next_section)
      {
        const auto &names  = id_field_names();
        const auto  wanted = [&](const std::string &name) {
          return cells &&
                 std::find(names.begin(), names.end(), name) != names.end();
        };
        const auto keep = [&](const std::string    &name,
                              const unsigned int    n_components,
                              std::vector<double> &&values) {
          const auto rank = std::find(names.begin(), names.end(), name);
          if (!cells || rank == names.end())
            return;
          if (n_components != 1)
            vtk.fail("cell field '" + name + "' has " +
                     std::to_string(n_components) +
                     " components; ids have one");
          if (id_name.empty() ||
              rank < std::find(names.begin(), names.end(), id_name))
            {
              id_name = name;
              ids     = std::move(values);
            }
        };
        next_section.clear();
        while (!vtk.at_end())
          {
            auto              words = vtk.keyword_line("an attribute");
            const std::string kind  = upper(words[0]);
            if (kind == "CELL_DATA" || kind == "POINT_DATA")
              {
                next_section = words;
                return;
              }
            if (kind == "SCALARS")
              {
                if (words.size() < 3)
                  vtk.fail("SCALARS needs a name and a data type");
                const unsigned int n_components =
                  words.size() > 3 ? vtk.count(words[3], "component count") : 1;
                if (n_components < 1 || n_components > 4)
                  vtk.fail("SCALARS with " + words[3] + " components");
                const auto table = vtk.keyword_line("LOOKUP_TABLE");
                if (upper(table[0]) != "LOOKUP_TABLE")
                  vtk.fail("expected LOOKUP_TABLE, found '" + table[0] + "'");
                auto values = vtk.values(n * n_components,
                                         words[2],
                                         "SCALARS " + words[1],
                                         wanted(words[1]));
                if (wanted(words[1]))
                  keep(words[1], n_components, std::move(values));
                vtk.skip_metadata();
              }
            else if (kind == "VECTORS" || kind == "NORMALS" ||
                     kind == "TENSORS")
              {
                if (words.size() < 3)
                  vtk.fail(kind + " needs a name and a data type");
                vtk.values(n * (kind == "TENSORS" ? 9 : 3),
                           words[2],
                           kind,
                           false);
                vtk.skip_metadata();
              }
            else if (kind == "FIELD")
              read_field(vtk, words, n, keep, wanted);
            else
              vtk.fail("attribute '" + words[0] +
                       "' (knee_contact reads SCALARS, VECTORS, NORMALS, "
                       "TENSORS and FIELD)");
          }
      }
    } // namespace



    Description<2>
    read_vtk(const std::string &file)
    {
      LegacyFile  vtk(file);
      std::string line;
      if (!vtk.line(line) || line.rfind("# vtk DataFile Version", 0) != 0)
        vtk.fail("not a legacy VTK file (no '# vtk DataFile Version' "
                 "header)");
      if (!vtk.line(line))
        vtk.fail("the file ends where the title should be");
      const std::string format = upper(trim(vtk.keyword_line("ASCII or "
                                                             "BINARY")[0]));
      if (format != "ASCII" && format != "BINARY")
        vtk.fail("expected ASCII or BINARY, found '" + format + "'");
      vtk.binary         = format == "BINARY";
      const auto dataset = vtk.keyword_line("DATASET");
      if (dataset.size() != 2 || upper(dataset[0]) != "DATASET" ||
          upper(dataset[1]) != "UNSTRUCTURED_GRID")
        vtk.fail("DATASET is not UNSTRUCTURED_GRID");

      std::vector<double>      points, offsets, connectivity, types, ids;
      std::string              id_name;
      std::size_t              n_points = 0, n_cells = 0;
      bool                     have_points = false, have_cells = false;
      std::vector<std::string> words;
      while (!vtk.at_end() || !words.empty())
        {
          if (words.empty())
            words = vtk.keyword_line("a section");
          const std::string kind = upper(words[0]);
          if (kind == "POINTS")
            {
              if (words.size() != 3)
                vtk.fail("POINTS needs a count and a data type");
              n_points = vtk.count(words[1], "point count");
              if (n_points > std::size_t(-1) / 3)
                vtk.fail("point count " + words[1] + " is too large");
              // A plane mesh has about as many cells as points (at least
              // half as many): the run's need, before anything is read.
              check_run_fits(2, n_points / 2., vtk.where("POINTS " + words[1]));
              points      = vtk.values(3 * n_points, words[2], "POINTS");
              have_points = true;
              vtk.skip_metadata();
              words.clear();
            }
          else if (kind == "CELLS")
            {
              if (words.size() != 3)
                vtk.fail("CELLS needs two counts");
              const std::size_t first  = vtk.count(words[1], "cell count");
              const std::size_t second = vtk.count(words[2], "cell list size");
              check_run_fits(2, first, vtk.where("CELLS " + words[1]));
              if (vtk.next_is("OFFSETS"))
                {
                  auto next = vtk.keyword_line("OFFSETS");
                  // 5.1: OFFSETS (cells + 1 of them, from 0) and
                  // CONNECTIVITY.
                  if (next.size() != 2 || first == 0)
                    vtk.fail("OFFSETS needs a data type and CELLS a count "
                             "of at least 1");
                  auto all_offsets = vtk.values(first, next[1], "OFFSETS");
                  if (all_offsets[0] != 0)
                    vtk.fail("OFFSETS do not start at 0");
                  vtk.skip_metadata();
                  next = vtk.keyword_line("CONNECTIVITY");
                  if (upper(next[0]) != "CONNECTIVITY" || next.size() != 2)
                    vtk.fail("expected CONNECTIVITY and a data type");
                  connectivity = vtk.values(second, next[1], "CONNECTIVITY");
                  vtk.skip_metadata();
                  if (all_offsets.back() != double(second))
                    vtk.fail("the last of the OFFSETS is not the "
                             "CONNECTIVITY size " +
                             std::to_string(second));
                  n_cells = first - 1;
                  offsets.assign(all_offsets.begin() + 1, all_offsets.end());
                  words.clear();
                }
              else
                {
                  // 4.2 and earlier: each cell's vertex count, then its
                  // vertices; the list is of type int.
                  const auto list = vtk.values(second, "int", "CELLS");
                  n_cells         = first;
                  std::size_t k   = 0;
                  for (std::size_t c = 0; c < n_cells; ++c)
                    {
                      if (k >= list.size())
                        vtk.fail("CELLS says " + words[2] +
                                 " numbers, the cells need more");
                      const double n = list[k];
                      if (n < 1 || n > 4 || n != std::floor(n))
                        vtk.fail("cell " + std::to_string(c) + " has " +
                                 std::to_string(n) + " vertices");
                      if (k + 1 + std::size_t(n) > list.size())
                        vtk.fail("CELLS says " + words[2] +
                                 " numbers, the cells need more");
                      connectivity.insert(connectivity.end(),
                                          list.begin() + k + 1,
                                          list.begin() + k + 1 +
                                            std::size_t(n));
                      k += 1 + std::size_t(n);
                      offsets.push_back(double(connectivity.size()));
                    }
                  if (k != list.size())
                    vtk.fail("CELLS says " + words[2] +
                             " numbers, the cells have " + std::to_string(k));
                  vtk.skip_metadata();
                  words.clear();
                }
              have_cells = true;
            }
          else if (kind == "CELL_TYPES")
            {
              if (words.size() != 2 ||
                  vtk.count(words[1], "cell type count") != n_cells ||
                  !have_cells)
                vtk.fail("CELL_TYPES count differs from CELLS");
              types = vtk.values(n_cells, "int", "CELL_TYPES");
              vtk.skip_metadata();
              words.clear();
            }
          else if (kind == "FIELD")
            {
              // Data of the whole set (TIME, CYCLE): not mesh data.
              read_field(vtk, words, std::size_t(-1), nullptr, nullptr);
              words.clear();
            }
          else if (kind == "CELL_DATA" || kind == "POINT_DATA")
            {
              const bool cells = kind == "CELL_DATA";
              if (words.size() != 2)
                vtk.fail(kind + " needs a count");
              const std::size_t n = vtk.count(words[1], kind + " count");
              if (n != (cells ? n_cells : n_points))
                vtk.fail(kind + " count differs from " +
                         (cells ? "CELLS" : "POINTS"));
              read_attributes(vtk, n, cells, ids, id_name, words);
            }
          else
            vtk.fail("section '" + words[0] +
                     "' (knee_contact reads POINTS, CELLS, CELL_TYPES, "
                     "CELL_DATA and POINT_DATA)");
        }
      if (!have_points || !have_cells || types.size() != n_cells)
        vtk.fail("the file has no POINTS, CELLS and CELL_TYPES");
      return unstructured_grid(points,
                               offsets,
                               connectivity,
                               types,
                               ids,
                               id_name.empty() ? "MaterialID" : id_name,
                               [&file](const std::string &what) {
                                 // Checks of the whole grid: no one line.
                                 throw std::runtime_error(input::cap(
                                   "Mesh/File: '" + file + "': " + what));
                               });
    }
  } // namespace mesh_readers
} // namespace knee_contact
