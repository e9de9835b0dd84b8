#include <knee_contact/mesh/mesh.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

    namespace
    {
      /**
       * Decoding of the DataArrays of a VTK XML file: base64 and zlib blocks
       * as VTK writes them (header of UInt32 or UInt64 byte counts).
       */
      class VtuArrays
      {
      public:
        VtuArrays(const std::string &file,
                  const bool         header_64,
                  const bool         compressed,
                  std::string_view   appended)
          : file(file)
          , header_64(header_64)
          , compressed(compressed)
          , appended(appended)
        {}

        /**
         * The @p n values of @p array (a DataArray element) as doubles.
         */
        std::vector<double>
        values(const boost::property_tree::ptree &array,
               const std::size_t                  n) const
        {
          const std::string name   = array.get("<xmlattr>.Name", "");
          const std::string type   = array.get("<xmlattr>.type", "");
          const std::string format = array.get("<xmlattr>.format", "");
          const std::map<std::string, unsigned int> sizes = {{"Int8", 1},
                                                             {"UInt8", 1},
                                                             {"Int16", 2},
                                                             {"UInt16", 2},
                                                             {"Int32", 4},
                                                             {"UInt32", 4},
                                                             {"Int64", 8},
                                                             {"UInt64", 8},
                                                             {"Float32", 4},
                                                             {"Float64", 8}};
          if (sizes.count(type) == 0)
            fail("DataArray '" + name + "' has type '" + type + "'");
          std::vector<double> result;
          if (format == "ascii")
            {
              std::stringstream stream(array.data());
              std::string       word;
              while (stream >> word && result.size() <= n)
                {
                  const auto value = input::number(word);
                  if (!value)
                    fail("DataArray '" + name + "': '" + word +
                         "' is not a finite number");
                  result.push_back(*value);
                }
            }
          else
            {
              std::string       bytes;
              const std::size_t expected = n * sizes.at(type);
              if (format == "binary")
                bytes = decode(trim_all(array.data()), name, expected);
              else if (format == "appended")
                {
                  const std::string offset_text =
                    array.get("<xmlattr>.offset", "");
                  std::size_t offset = 0;
                  try
                    {
                      offset = std::stoull(offset_text);
                    }
                  catch (...)
                    {
                      fail("DataArray '" + name + "' has no valid offset");
                    }
                  if (offset >= appended.size())
                    fail("DataArray '" + name + "': offset " + offset_text +
                         " is beyond the appended data");
                  bytes = unpack(appended.substr(offset), name, expected);
                }
              else
                fail("DataArray '" + name + "' has format '" + format +
                     "' (ascii, binary or appended)");
              const unsigned int size = sizes.at(type);
              if (bytes.size() < n * size)
                fail("DataArray '" + name + "' holds " +
                     std::to_string(bytes.size() / size) + " values, " +
                     std::to_string(n) + " expected");
              for (std::size_t i = 0; i < n; ++i)
                result.push_back(number(bytes.data() + i * size, type));
            }
          if (result.size() != n)
            fail("DataArray '" + name + "' holds " +
                 std::to_string(result.size()) + " values, " +
                 std::to_string(n) + " expected");
          return result;
        }

      private:
        [[noreturn]] void
        fail(const std::string &what) const
        {
          throw std::runtime_error(
            input::cap("Mesh/File: '" + file + "': " + what));
        }

        static std::string
        trim_all(const std::string &text)
        {
          std::string result;
          for (const char c : text)
            if (!std::isspace(static_cast<unsigned char>(c)))
              result += c;
          return result;
        }

        std::string
        base64(const std::string &text, const std::string &name) const
        {
          static const std::string alphabet =
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
          std::string  result;
          unsigned int buffer = 0, bits = 0;
          for (const char c : text)
            {
              if (c == '=')
                break;
              const auto k = alphabet.find(c);
              if (k == std::string::npos)
                fail("DataArray '" + name + "' is not base64");
              buffer = (buffer << 6) | k;
              bits += 6;
              if (bits >= 8)
                {
                  bits -= 8;
                  result += static_cast<char>((buffer >> bits) & 0xff);
                }
            }
          return result;
        }

        std::uint64_t
        header_item(const std::string_view bytes, const std::size_t i) const
        {
          const std::size_t size = header_64 ? 8 : 4;
          if (bytes.size() < (i + 1) * size)
            fail("a DataArray's header is cut off");
          std::uint64_t value = 0;
          for (std::size_t b = 0; b < size; ++b)
            value |=
              std::uint64_t(static_cast<unsigned char>(bytes[i * size + b]))
              << (8 * b);
          return value;
        }

        /** Inline binary: base64, the header apart if compressed. */
        std::string
        decode(const std::string &text,
               const std::string &name,
               const std::size_t  expected) const
        {
          const std::size_t size       = header_64 ? 8 : 4;
          const auto        b64_length = [](const std::size_t bytes) {
            return 4 * ((bytes + 2) / 3);
          };
          if (!compressed)
            {
              // VTK encodes the header and the data as two base64 streams
              // (the header's ends in '='); other writers as one.
              const std::size_t header_length = b64_length(size);
              if (text.size() >= header_length &&
                  text[header_length - 1] == '=')
                return unpack(base64(text.substr(0, header_length), name) +
                                base64(text.substr(header_length), name),
                              name,
                              expected);
              return unpack(base64(text, name), name, expected);
            }
          const std::string first =
            base64(text.substr(0, b64_length(3 * size)), name);
          const std::uint64_t n_blocks = header_item(first, 0);
          if (n_blocks > text.size())
            fail("DataArray '" + name + "': block count " +
                 std::to_string(n_blocks) + " is more than it can hold");
          const std::size_t header_length = b64_length((3 + n_blocks) * size);
          if (header_length > text.size())
            fail("DataArray '" + name + "' is cut off");
          return unpack(base64(text.substr(0, header_length), name) +
                          base64(text.substr(header_length), name),
                        name,
                        expected,
                        (3 + n_blocks) * size);
        }

        /**
         * Header and data (raw bytes): the data, inflated if compressed.
         * @p expected: the bytes the array must hold (compressed data must
         * say exactly that before anything is inflated, so that a header
         * cannot ask for memory the file does not justify).
         * @p header_bytes: the length of a header padded by base64.
         */
        std::string
        unpack(const std::string_view bytes,
               const std::string     &name,
               const std::size_t      expected,
               std::size_t            header_bytes = 0) const
        {
          const std::size_t size = header_64 ? 8 : 4;
          if (!compressed)
            {
              const std::uint64_t n = header_item(bytes, 0);
              if (n > bytes.size() - size)
                fail("DataArray '" + name + "' says " + std::to_string(n) +
                     " bytes, holds " + std::to_string(bytes.size() - size));
              return std::string(bytes.substr(size, n));
            }
          const std::uint64_t n_blocks = header_item(bytes, 0),
                              block    = header_item(bytes, 1),
                              last     = header_item(bytes, 2);
          if (n_blocks > bytes.size() || block > (std::uint64_t(1) << 31) ||
              last > block)
            fail("DataArray '" + name + "' has an impossible header");
          const std::uint64_t declared =
            n_blocks == 0 ? 0
                          : (n_blocks - 1) * block + (last != 0 ? last : block);
          if (declared != expected)
            fail("DataArray '" + name + "' holds " + std::to_string(declared) +
                 " bytes, " + std::to_string(expected) + " expected");
          std::size_t at =
            std::max<std::size_t>(header_bytes, (3 + n_blocks) * size);
          if (at > bytes.size())
            fail("DataArray '" + name + "' is cut off");
          std::string result;
          for (std::uint64_t b = 0; b < n_blocks; ++b)
            {
              const std::uint64_t length = header_item(bytes, 3 + b);
              if (length > bytes.size() - at)
                fail("DataArray '" + name + "' is cut off");
              uLongf inflated = (b + 1 == n_blocks && last != 0) ? last : block;
              std::string out(inflated, '\0');
              if (uncompress(reinterpret_cast<Bytef *>(out.data()),
                             &inflated,
                             reinterpret_cast<const Bytef *>(bytes.data() + at),
                             length) != Z_OK)
                fail("DataArray '" + name +
                     "': a zlib block does not "
                     "inflate");
              result += out.substr(0, inflated);
              at += length;
            }
          return result;
        }

        static double
        number(const char *p, const std::string &type)
        {
          const auto get = [p](auto value) {
            std::memcpy(&value, p, sizeof(value));
            return static_cast<double>(value);
          };
          if (type == "Int8")
            return get(std::int8_t());
          if (type == "UInt8")
            return get(std::uint8_t());
          if (type == "Int16")
            return get(std::int16_t());
          if (type == "UInt16")
            return get(std::uint16_t());
          if (type == "Int32")
            return get(std::int32_t());
          if (type == "UInt32")
            return get(std::uint32_t());
          if (type == "Int64")
            return get(std::int64_t());
          if (type == "UInt64")
            return get(std::uint64_t());
          if (type == "Float32")
            return get(float());
          return get(double());
        }

        const std::string file;
        const bool        header_64;
        const bool        compressed;
        /** The raw appended data, a view into the mapped file. */
        const std::string_view appended;
      };

      /**
       * The deepest nesting of XML elements that a VTU file may have. A VTK
       * UnstructuredGrid needs six levels (VTKFile, UnstructuredGrid, Piece,
       * Cells, DataArray, and InformationKey in VTK 9's metadata); Boost's
       * XML parser recurses once per level on the stack, so an unbounded
       * depth is a crash (100 000 levels overflowed it).
       */
      constexpr unsigned int max_xml_depth = 64;

      /**
       * The line at which the nesting of @p text first exceeds
       * max_xml_depth, or 0. A scan of the markup only: comments, CDATA,
       * processing instructions and declarations are skipped, quoted
       * attribute values may hold '>' and '/'. Written by hand because
       * Boost's parser (the one that recurses) is the only XML parser here.
       */
      std::size_t
      too_deep_at(const std::string &text)
      {
        unsigned int depth = 0;
        std::size_t  line  = 1;
        const auto   skip  = [&](std::size_t from, const char *end) {
          const auto at = text.find(end, from);
          if (at == std::string::npos)
            return text.size();
          line += std::count(text.begin() + from, text.begin() + at, '\n');
          return at + std::strlen(end);
        };
        for (std::size_t i = 0; i < text.size();)
          {
            if (text[i] == '\n')
              ++line;
            if (text[i] != '<')
              {
                ++i;
                continue;
              }
            if (text.compare(i, 4, "<!--") == 0)
              i = skip(i, "-->");
            else if (text.compare(i, 9, "<![CDATA[") == 0)
              i = skip(i, "]]>");
            else if (text.compare(i, 2, "<?") == 0)
              i = skip(i, "?>");
            else if (text.compare(i, 2, "<!") == 0)
              i = skip(i, ">");
            else if (text.compare(i, 2, "</") == 0)
              {
                if (depth > 0)
                  --depth;
                i = skip(i, ">");
              }
            else
              {
                // An opening tag: to its '>', outside quoted values.
                char        quote = 0;
                std::size_t j     = i + 1;
                for (; j < text.size(); ++j)
                  {
                    if (text[j] == '\n')
                      ++line;
                    if (quote != 0)
                      quote = text[j] == quote ? 0 : quote;
                    else if (text[j] == '"' || text[j] == '\'')
                      quote = text[j];
                    else if (text[j] == '>')
                      break;
                  }
                if (j < text.size() && text[j - 1] != '/' &&
                    ++depth > max_xml_depth)
                  return line;
                i = j + 1;
              }
          }
        return 0;
      }
    } // namespace



    Description<2>
    read_vtu(const std::string &file)
    {
      // Mapped, not read: the XML part is copied out below, the appended
      // data are decoded where they lie.
      const MappedFile       mapped(file);
      const std::string_view whole = mapped.text();
      const std::uintmax_t   size  = whole.size();
      const auto             fail  = [&file](const std::string &what) {
        throw std::runtime_error(
          input::cap("Mesh/File: '" + file + "': " + what));
      };

      // The sizes first, from the Piece tag near the start (before it only
      // the header and FieldData): the run they ask for must fit, and the
      // file may hold no more than such a mesh can take (4 kB per point
      // and cell is generous: ASCII coordinates, connectivity and a few
      // dozen data arrays), so that nothing of a huge file is touched.
      {
        constexpr std::size_t  head_length = 1 << 16;
        const std::string_view head        = whole.substr(0, head_length);
        const auto             piece_at    = head.find("<Piece");
        if (piece_at == std::string::npos)
          fail("no <Piece> in the first " + std::to_string(head_length >> 10) +
               " kB (not a VTK UnstructuredGrid file?)");
        const auto attribute = [&](const std::string &name) {
          const auto tag_end = head.find('>', piece_at);
          const auto at      = head.find(name + "=\"", piece_at);
          if (tag_end == std::string::npos || at == std::string::npos ||
              at > tag_end)
            fail("the Piece tag has no " + name);
          const auto  value = head.substr(at + name.size() + 2, 20);
          std::size_t n = 0, digits = 0;
          while (digits < value.size() &&
                 std::isdigit(static_cast<unsigned char>(value[digits])) &&
                 digits < 19)
            n = 10 * n + (value[digits++] - '0');
          if (digits == 0 || digits == value.size() || value[digits] != '"')
            fail("Piece has no valid " + name);
          return n;
        };
        const double n_points = attribute("NumberOfPoints"),
                     n_cells  = attribute("NumberOfCells");
        check_run_fits(2,
                       std::max(n_cells, n_points / 2.),
                       "Mesh/File: '" + file + "': NumberOfPoints " +
                         std::to_string(std::size_t(n_points)) +
                         ", NumberOfCells " +
                         std::to_string(std::size_t(n_cells)));
        const double most = 4096. * (n_points + n_cells) + (1 << 20);
        if (size > most)
          fail("the file's " + std::to_string(size) + " bytes are more than " +
               std::to_string(std::size_t(n_points)) + " points and " +
               std::to_string(std::size_t(n_cells)) + " cells take (at most " +
               std::to_string(std::size_t(most)) + ": 4 kB each and 1 MB)");
      }

      // Raw appended data is not XML: cut it off before parsing.
      std::string_view appended;
      std::string      text;
      const auto       appended_at = whole.find("<AppendedData");
      if (appended_at != std::string::npos)
        {
          const auto tag_end = whole.find('>', appended_at);
          const auto start   = whole.find('_', tag_end);
          const auto end     = whole.rfind("</AppendedData>");
          if (tag_end == std::string::npos || start == std::string::npos ||
              end == std::string::npos || end < start)
            fail("the AppendedData section is cut off");
          if (whole.substr(appended_at, tag_end - appended_at)
                .find("\"raw\"") == std::string::npos)
            fail("appended data that is not raw (write it raw, or as "
                 "ascii or binary DataArrays)");
          appended = whole.substr(start + 1, end - start - 1);
          text     = std::string(whole.substr(0, appended_at)) + "</VTKFile>";
        }
      else
        text = std::string(whole);
      if (const auto line = too_deep_at(text))
        fail("line " + std::to_string(line) + ": XML elements nested " +
             "deeper than " + std::to_string(max_xml_depth) +
             " levels (a VTU file needs 6; the limit bounds the XML " +
             "parser's recursion)");
      boost::property_tree::ptree tree;
      try
        {
          std::stringstream stream(text);
          boost::property_tree::read_xml(stream, tree);
        }
      catch (const boost::property_tree::xml_parser_error &exc)
        {
          fail("line " + std::to_string(exc.line()) + ": " + exc.message() +
               " (not a VTK XML file?)");
        }
      const auto root = tree.get_child_optional("VTKFile");
      if (!root)
        fail("no VTKFile element");
      if (root->get("<xmlattr>.type", "") != "UnstructuredGrid")
        fail("VTKFile type is '" + root->get("<xmlattr>.type", "") +
             "'; knee_contact reads UnstructuredGrid");
      if (root->get("<xmlattr>.byte_order", "LittleEndian") != "LittleEndian")
        fail("big-endian data (write it little-endian)");
      const std::string header = root->get("<xmlattr>.header_type", "UInt32");
      if (header != "UInt32" && header != "UInt64")
        fail("header_type '" + header + "'");
      const std::string compressor = root->get("<xmlattr>.compressor", "");
      if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
        fail("compressor '" + compressor +
             "' (knee_contact reads zlib and uncompressed data)");
      const auto pieces = root->get_child_optional("UnstructuredGrid");
      if (!pieces || pieces->count("Piece") != 1)
        fail("knee_contact reads an UnstructuredGrid of one Piece");
      const auto &piece = pieces->get_child("Piece");
      const auto  count = [&](const std::string &attribute) {
        const std::string text = piece.get("<xmlattr>." + attribute, "");
        std::size_t       n    = 0;
        try
          {
            n = std::stoull(text);
          }
        catch (...)
          {
            fail("Piece has no valid " + attribute);
          }
        if (n > size)
          fail(attribute + " " + text + " is more than the file's " +
               std::to_string(size) + " bytes can hold");
        return n;
      };
      const std::size_t n_points = count("NumberOfPoints"),
                        n_cells  = count("NumberOfCells");
      const VtuArrays arrays(file,
                             header == "UInt64",
                             !compressor.empty(),
                             appended);
      const auto      array = [&](const std::string &section,
                             const std::string &name,
                             const std::size_t  n,
                             const bool         required) {
        const auto parent = piece.get_child_optional(section);
        if (parent)
          for (const auto &[tag, child] : *parent)
            if (tag == "DataArray" &&
                (name.empty() || child.get("<xmlattr>.Name", "") == name))
              return arrays.values(child, n);
        if (required)
          fail("no DataArray '" + name + "' in " + section);
        return std::vector<double>();
      };

      const auto points      = array("Points", "", 3 * n_points, true);
      const auto offsets     = array("Cells", "offsets", n_cells, true);
      const auto types       = array("Cells", "types", n_cells, true);
      const auto n_connected = n_cells == 0 ? 0. : offsets.back();
      if (!(n_connected >= 0 && n_connected <= size))
        fail("the last offset is not a connectivity length");
      const auto connectivity =
        array("Cells", "connectivity", std::size_t(n_connected), true);
      // The first cell field of id_field_names() the file has.
      std::vector<double> ids;
      std::string         id_name = "MaterialID";
      for (const auto &name : id_field_names())
        if (ids.empty())
          {
            ids = array("CellData", name, n_cells, false);
            if (!ids.empty())
              id_name = name;
          }

      return unstructured_grid(
        points, offsets, connectivity, types, ids, id_name, fail);
    }



    namespace internal
    {
      Description<2>
      unstructured_grid(const std::vector<double> &points,
                        const std::vector<double> &offsets,
                        const std::vector<double> &connectivity,
                        const std::vector<double> &types,
                        const std::vector<double> &ids,
                        const std::string         &id_name,
                        const std::function<void(const std::string &)> &fail)
      {
        const std::size_t n_points = points.size() / 3;
        const std::size_t n_cells  = types.size();
        const auto        text_of  = [](const double value) {
          std::ostringstream stream;
          stream << value;
          return stream.str();
        };
        Description<2> mesh;
        for (std::size_t i = 0; i < n_points; ++i)
          {
            for (unsigned int d = 0; d < 3; ++d)
              if (!std::isfinite(points[3 * i + d]))
                fail("point " + std::to_string(i) +
                     " has a coordinate that is not finite");
            if (points[3 * i + 2] != 0)
              fail("point " + std::to_string(i) +
                   " has z != 0: knee_contact meshes lie in the x-y plane");
            mesh.vertices.emplace_back(points[3 * i], points[3 * i + 1]);
          }
        double begin = 0;
        for (std::size_t c = 0; c < n_cells; ++c)
          {
            const double                        end        = offsets[c];
            const std::map<double, std::size_t> n_vertices = {{1, 1},
                                                              {3, 2},
                                                              {5, 3},
                                                              {9, 4}};
            if (types[c] != std::floor(types[c]) || end != std::floor(end))
              fail("cell " + std::to_string(c) +
                   ": a type or an offset that is not an integer");
            if (n_vertices.count(types[c]) == 0)
              fail("cell " + std::to_string(c) + " has VTK type " +
                   text_of(types[c]) +
                   ", not a vertex (1), line (3), triangle (5) or "
                   "quadrilateral (9)");
            // Offsets that climb past the connectivity and come back down
            // would pass the count test below and read beyond it.
            if (end > static_cast<double>(connectivity.size()))
              fail("cell " + std::to_string(c) + ": offset " + text_of(end) +
                   " is beyond the " + std::to_string(connectivity.size()) +
                   " connectivity entries");
            if (end - begin != n_vertices.at(types[c]))
              fail("cell " + std::to_string(c) + " of type " +
                   std::to_string(int(types[c])) + " has " +
                   text_of(end - begin) + " vertices");
            std::vector<unsigned int> vertices;
            for (auto k = std::size_t(begin); k < std::size_t(end); ++k)
              {
                const double v = connectivity[k];
                if (v < 0 || v >= n_points || v != std::floor(v))
                  fail("cell " + std::to_string(c) + " refers to point " +
                       text_of(v) + ", but there are " +
                       std::to_string(n_points) + " points");
                vertices.push_back(static_cast<unsigned int>(v));
              }
            begin = end;
            if (std::set<unsigned int>(vertices.begin(), vertices.end())
                  .size() != vertices.size())
              fail("cell " + std::to_string(c) + " names a point twice");
            const double id = ids.empty() ? 0 : ids[c];
            if (id < 0 || id >= 255 || id != std::floor(id))
              fail(id_name + " " + text_of(id) + " of cell " +
                   std::to_string(c) + " is not in 0..254");
            if (types[c] == 3)
              add_boundary_line(mesh,
                                vertices[0],
                                vertices[1],
                                static_cast<types::boundary_id>(id));
            else if (types[c] != 1)
              add_cell(mesh, vertices, static_cast<types::material_id>(id));
          }
        if (mesh.cells.empty())
          fail("no triangles or quadrilaterals");
        GridTools::delete_unused_vertices(mesh.vertices,
                                          mesh.cells,
                                          mesh.subcells);
        return mesh;
      }
    } // namespace internal
  }   // namespace mesh_readers
} // namespace knee_contact
