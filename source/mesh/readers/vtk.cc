#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <cmath>

namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

    void
    check_vtk(const std::string &file)
    {
      Lines       lines(file);
      std::string line;
      const auto  expect_line = [&](const std::string &what) {
        if (!lines.next(line))
          lines.fail("the file ends where " + what + " should be");
        return trim(line);
      };
      if (expect_line("the header").rfind("# vtk DataFile Version", 0) != 0)
        lines.fail("not a legacy VTK file (no '# vtk DataFile Version' "
                   "header; knee_contact reads ASCII .vtk, not .vtu)");
      expect_line("the title");
      if (upper(expect_line("ASCII")) != "ASCII")
        lines.fail("a binary VTK file: knee_contact reads ASCII .vtk");
      if (upper(expect_line("DATASET")) != "DATASET UNSTRUCTURED_GRID")
        lines.fail("DATASET is not UNSTRUCTURED_GRID");

      // The rest as whitespace separated words, with their lines.
      std::vector<std::pair<std::string, unsigned long>> words;
      while (lines.next(line))
        {
          std::stringstream stream(line);
          std::string       word;
          while (stream >> word)
            words.emplace_back(word, lines.number);
        }
      std::size_t at   = 0;
      const auto  word = [&](const std::string &what) -> const std::string  &{
        if (at >= words.size())
          lines.fail("the file ends where " + what + " should be");
        lines.number = words[at].second;
        return words[at++].first;
      };
      const auto count = [&](const std::string &what) {
        const std::string &text = word(what);
        const long long    n    = to_integer(text, lines);
        if (n < 0 || static_cast<std::uintmax_t>(n) > lines.size)
          lines.fail(what + " " + text + " is more than the file's " +
                     std::to_string(lines.size) + " bytes can hold");
        return static_cast<std::size_t>(n);
      };
      const auto keyword = [&](const std::string &expected) {
        const std::string &found = word(expected);
        if (upper(found) != expected)
          lines.fail("expected " + expected + ", found '" + found + "'");
      };

      keyword("POINTS");
      const std::size_t n_points = count("point count");
      word("the point type");
      for (std::size_t i = 0; i < 3 * n_points; ++i)
        to_number(word("a coordinate"), lines);
      keyword("CELLS");
      const std::size_t        n_cells = count("cell count");
      const std::size_t        n_ints  = count("cell list size");
      std::vector<std::size_t> sizes;
      std::size_t              used = 0;
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const std::size_t n = count("vertex count");
          if (n < 1 || n > 4)
            lines.fail("cell " + std::to_string(c) + " has " +
                       std::to_string(n) + " vertices");
          std::set<long long> distinct;
          for (std::size_t k = 0; k < n; ++k)
            {
              const long long v = to_integer(word("a vertex"), lines);
              if (v < 0 || static_cast<std::size_t>(v) >= n_points)
                lines.fail("cell " + std::to_string(c) + " refers to point " +
                           std::to_string(v) + ", but there are " +
                           std::to_string(n_points) + " points");
              distinct.insert(v);
            }
          if (distinct.size() != n)
            lines.fail("cell " + std::to_string(c) + " names a point twice");
          sizes.push_back(n);
          used += n + 1;
        }
      if (used != n_ints)
        lines.fail("CELLS says " + std::to_string(n_ints) +
                   " numbers, the cells have " + std::to_string(used));
      keyword("CELL_TYPES");
      if (count("cell type count") != n_cells)
        lines.fail("CELL_TYPES count differs from CELLS");
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const long long type = to_integer(word("a cell type"), lines);
          // 1 vertex, 3 line, 5 triangle, 9 quadrilateral.
          const std::map<long long, std::size_t> n_vertices = {{1, 1},
                                                               {3, 2},
                                                               {5, 3},
                                                               {9, 4}};
          if (n_vertices.count(type) == 0)
            lines.fail("cell type " + std::to_string(type) +
                       " is not a vertex (1), line (3), triangle (5) or "
                       "quadrilateral (9); knee_contact reads linear 2D "
                       "cells");
          if (n_vertices.at(type) != sizes[c])
            lines.fail("cell " + std::to_string(c) + " of type " +
                       std::to_string(type) + " has " +
                       std::to_string(sizes[c]) + " vertices");
        }
      if (at == words.size())
        return;
      keyword("CELL_DATA");
      if (count("cell data count") != n_cells)
        lines.fail("CELL_DATA count differs from CELLS");
      while (at < words.size())
        {
          keyword("SCALARS");
          const std::string name = word("a field name");
          if (name != "MaterialID" && name != "ManifoldID")
            lines.fail("field '" + name +
                       "': knee_contact reads MaterialID and ManifoldID "
                       "(boundary ids are the MaterialID of line cells)");
          if (word("the field type") != "int")
            lines.fail("field '" + name + "' must have type int");
          if (words[at].first == "1")
            ++at;
          keyword("LOOKUP_TABLE");
          word("the lookup table");
          for (std::size_t c = 0; c < n_cells; ++c)
            {
              const long long id = to_integer(word("an id"), lines);
              if (id < 0 || id >= 255)
                lines.fail(name + " " + std::to_string(id) +
                           " is not in 0..254");
            }
        }
    }
  } // namespace mesh_readers
} // namespace knee_contact
