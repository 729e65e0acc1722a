// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// VTK XML files in either byte order (issue 27): a valid ascii .vtu that
// declares byte_order="BigEndian" (as another simulator's examples do) was
// refused, and big-endian binary data could not be read at all.
//
// A beam of tetrahedra (45 nodes, 80 tetrahedra, coordinates perturbed so
// that every byte of every double matters) is written as .vtu, and its
// boundary as .vtp, in each binary encoding VTK writes (inline base64,
// inline base64 + zlib, appended raw, appended raw + zlib, appended base64)
// with UInt32 and UInt64 headers, once little-endian and once big-endian
// (the test swaps every value and every header size itself). Points are
// Float64, connectivity Int64, offsets Int32 and types UInt8, so values of
// 8, 4 and 1 bytes are swapped; the zlib arrays are cut into 256-byte
// blocks, so a header holds several block sizes. Each big-endian file must
// read to exactly the nodes and cells of its little-endian twin, and that
// twin to exactly the beam. Ascii files must read whatever byte_order they
// declare (BigEndian, or a value that is no byte order at all).
//
// Bad input: a big-endian array cut short (raw, base64, zlib) is refused
// with the sizes its header really gives, read in the file's byte order,
// and the file's name; binary data under an unknown byte_order are refused.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/generators.h>
#include <palpate/mesh/mesh_file.h>

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "../tests.h"

#include "../mesh_writers.h"

namespace
{
  using Bytes = std::vector<unsigned char>;
  using palpate::MeshData;

  enum class Encoding
  {
    ascii,
    base64,
    base64_zlib,
    appended_raw,
    appended_raw_zlib,
    appended_base64
  };

  const char *
  encoding_name(const Encoding e)
  {
    switch (e)
      {
        case Encoding::ascii:
          return "ascii";
        case Encoding::base64:
          return "inline base64";
        case Encoding::base64_zlib:
          return "inline base64 + zlib";
        case Encoding::appended_raw:
          return "appended raw";
        case Encoding::appended_raw_zlib:
          return "appended raw + zlib";
        case Encoding::appended_base64:
          return "appended base64";
      }
    return "?";
  }

  bool
  compressed(const Encoding e)
  {
    return e == Encoding::base64_zlib || e == Encoding::appended_raw_zlib;
  }

  bool
  host_is_little_endian()
  {
    const std::uint16_t one = 1;
    unsigned char       first;
    std::memcpy(&first, &one, 1);
    return first == 1;
  }

  /**
   * The bytes of @p v in the requested byte order: this machine's bytes,
   * each value reversed if the order asked for is not the machine's.
   */
  template <typename T>
  Bytes
  bytes_of(const std::vector<T> &v, const bool big_endian)
  {
    Bytes b(v.size() * sizeof(T));
    std::memcpy(b.data(), v.data(), b.size());
    if (big_endian == host_is_little_endian())
      for (std::size_t i = 0; i < b.size(); i += sizeof(T))
        std::reverse(b.begin() + i, b.begin() + i + sizeof(T));
    return b;
  }

  /** Header values (sizes) as the file stores them: UInt32 or UInt64. */
  Bytes
  header_bytes(const std::vector<std::uint64_t> &values,
               const bool                        header_64,
               const bool                        big_endian)
  {
    if (header_64)
      return bytes_of(values, big_endian);
    return bytes_of(std::vector<std::uint32_t>(values.begin(), values.end()),
                    big_endian);
  }

  /** One array as VTK stores it: its header, then its (packed) data. */
  struct Block
  {
    Bytes header, data;
  };

  /**
   * The header and data of one binary array. zlib: the data cut into
   * 256-byte blocks (the last one shorter), each compressed, and the header
   * lists the number of blocks, the block size, the last block's size and
   * every compressed size.
   */
  Block
  block(const Bytes &array, const bool zlib, const bool h64, const bool big)
  {
    if (!zlib)
      return {header_bytes({array.size()}, h64, big), array};
    constexpr std::size_t      block_size = 256;
    const std::size_t          n = (array.size() + block_size - 1) / block_size;
    std::vector<std::uint64_t> header = {n,
                                         block_size,
                                         array.size() % block_size};
    Bytes                      packed;
    for (std::size_t b = 0; b < n; ++b)
      {
        const std::size_t begin = b * block_size;
        const std::size_t size  = std::min(block_size, array.size() - begin);
        uLongf            csize = compressBound(size);
        Bytes             out(csize);
        compress(out.data(), &csize, array.data() + begin, size);
        out.resize(csize);
        header.push_back(csize);
        packed = concat(packed, out);
      }
    return {header_bytes(header, h64, big), packed};
  }

  /** What a file holds: points and cells, or points and polygons. */
  struct Arrays
  {
    std::vector<double>       points;
    std::vector<std::int64_t> connectivity;
    std::vector<std::int32_t> offsets;
    std::vector<std::uint8_t> types;
  };

  template <typename T>
  std::string
  ascii(const std::vector<T> &v)
  {
    std::ostringstream s;
    s << std::setprecision(17);
    for (const T x : v)
      s << +x << ' ';
    return s.str();
  }

  /**
   * A .vtu (or .vtp if @p polydata) of @p a in encoding @p e, in the byte
   * order @p big_endian, with UInt64 headers if @p h64; @p byte_order is
   * what the file declares. If @p cut > 0, the last array loses that many
   * bytes (base64 characters if base64) at its end: a truncated array.
   */
  std::string
  vtk_xml(const Arrays      &a,
          const bool         polydata,
          const Encoding     e,
          const bool         big_endian,
          const bool         h64,
          const std::string &byte_order,
          const std::size_t  cut = 0)
  {
    const bool  zlib = compressed(e);
    std::string s    = "<?xml version=\"1.0\"?>\n<VTKFile type=\"" +
                    std::string(polydata ? "PolyData" : "UnstructuredGrid") +
                    "\" version=\"1.0\" byte_order=\"" + byte_order +
                    "\" header_type=\"" + (h64 ? "UInt64" : "UInt32") + "\"" +
                    (zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") +
                    ">\n<" + (polydata ? "PolyData" : "UnstructuredGrid") +
                    ">\n<Piece NumberOfPoints=\"" +
                    std::to_string(a.points.size() / 3) + "\" " +
                    (polydata ? "NumberOfPolys" : "NumberOfCells") + "=\"" +
                    std::to_string(a.offsets.size()) + "\">\n";
    const std::vector<Bytes>       arrays = {bytes_of(a.points, big_endian),
                                             bytes_of(a.connectivity, big_endian),
                                             bytes_of(a.offsets, big_endian),
                                             bytes_of(a.types, big_endian)};
    const std::vector<std::string> texts  = {ascii(a.points),
                                             ascii(a.connectivity),
                                             ascii(a.offsets),
                                             ascii(a.types)};
    const char        *type_name[] = {"Float64", "Int64", "Int32", "UInt8"};
    const char        *name[] = {"Points", "connectivity", "offsets", "types"};
    const unsigned int n_arrays = polydata ? 3 : 4;
    const bool         appended = e == Encoding::appended_raw ||
                          e == Encoding::appended_raw_zlib ||
                          e == Encoding::appended_base64;
    std::string data; // the appended section
    for (unsigned int k = 0; k < n_arrays; ++k)
      {
        if (k == 0)
          s += "<Points>\n";
        if (k == 1)
          s += polydata ? "<Polys>\n" : "<Cells>\n";
        s += std::string("<DataArray type=\"") + type_name[k] + "\" Name=\"" +
             name[k] + "\"" + (k == 0 ? " NumberOfComponents=\"3\"" : "");
        const bool  last = k + 1 == n_arrays;
        const Block b    = block(arrays[k], zlib, h64, big_endian);
        std::string text;
        if (e == Encoding::ascii)
          text = texts[k];
        else if (e == Encoding::base64_zlib || e == Encoding::appended_base64)
          // VTK encodes the header and the data separately; other writers
          // encode them together, which palpate reads inline.
          text = base64(b.header) + base64(b.data);
        else if (e == Encoding::base64)
          text = base64(concat(b.header, b.data));
        else
          text = std::string(b.header.begin(), b.header.end()) +
                 std::string(b.data.begin(), b.data.end());
        if (last && cut > 0)
          text.resize(text.size() - cut);
        if (appended)
          {
            s += " format=\"appended\" offset=\"" +
                 std::to_string(data.size()) + "\"/>\n";
            data += text;
          }
        else
          s += std::string(" format=\"") +
               (e == Encoding::ascii ? "ascii" : "binary") + "\">\n" + text +
               "\n</DataArray>\n";
        if (k == 0)
          s += "</Points>\n";
        if (last)
          s += polydata ? "</Polys>\n" : "</Cells>\n";
      }
    s += std::string("</Piece>\n</") +
         (polydata ? "PolyData" : "UnstructuredGrid") + ">\n";
    if (appended)
      s += std::string("<AppendedData encoding=\"") +
           (e == Encoding::appended_base64 ? "base64" : "raw") + "\">\n_" +
           data + "\n</AppendedData>\n";
    return s + "</VTKFile>\n";
  }

  /** The beam's tetrahedra (or, if @p polydata, its boundary triangles). */
  Arrays
  arrays_of(const MeshData &d, const bool polydata)
  {
    Arrays a;
    for (const auto &x : d.nodes)
      a.points.insert(a.points.end(), x.begin(), x.end());
    const auto add = [&](const auto &cell, const std::uint8_t type) {
      a.connectivity.insert(a.connectivity.end(), cell.begin(), cell.end());
      a.offsets.push_back(a.connectivity.size());
      a.types.push_back(type);
    };
    if (polydata)
      for (const auto &t : d.triangles)
        add(t, 5);
    else
      for (const auto &t : d.tetrahedra)
        add(t, 10);
    return a;
  }

  /** Same nodes, bit for bit, and the same cells in the same order. */
  bool
  identical(const MeshData &a, const MeshData &b, const bool polydata)
  {
    return a.nodes == b.nodes && (polydata ? a.triangles == b.triangles :
                                             a.tetrahedra == b.tetrahedra);
  }

  MeshData
  read(const std::string &file, const bool polydata)
  {
    return polydata ? palpate::read_vtp(file) : palpate::read_mesh_file(file);
  }

  /** Read @p text as @p file and log the error it must give. */
  void
  refused(const std::string &what,
          const std::string &file,
          const std::string &text,
          const bool         polydata = false)
  {
    write_file(file, text);
    try
      {
        const MeshData d = read(file, polydata);
        deallog << what << ": ACCEPTED, " << d.nodes.size() << " nodes"
                << std::endl;
      }
    catch (const palpate::InputError &e)
      {
        deallog << what << ": refused" << std::endl << e.what() << std::endl;
      }
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  palpate::Scene scene;
  auto          &p           = scene.parameters.mesh;
  p.beam_subdivisions_length = 4;
  p.beam_subdivisions_width  = 2;
  p.beam_subdivisions_height = 2;
  MeshData beam              = palpate::generate_beam(p);
  // Perturbed coordinates: no byte of any double is zero or repeated by
  // chance, so a value swapped wrongly (or not at all) cannot pass.
  for (std::size_t i = 0; i < beam.nodes.size(); ++i)
    for (unsigned int d = 0; d < 3; ++d)
      beam.nodes[i][d] += 1e-4 * std::sin(1.0 + 3 * i + d);
  deallog << "beam: " << beam.nodes.size() << " nodes, "
          << beam.tetrahedra.size() << " tetrahedra, " << beam.triangles.size()
          << " boundary triangles" << std::endl;

  for (const bool polydata : {false, true})
    {
      const std::string ext = polydata ? ".vtp" : ".vtu";
      const Arrays      a   = arrays_of(beam, polydata);
      deallog << (polydata ? "VTP (boundary triangles)" : "VTU (tetrahedra)")
              << std::endl;
      for (const Encoding e : {Encoding::base64,
                               Encoding::base64_zlib,
                               Encoding::appended_raw,
                               Encoding::appended_raw_zlib,
                               Encoding::appended_base64})
        for (const bool h64 : {false, true})
          {
            const std::string stem = std::string("beam-") +
                                     std::to_string(int(e)) +
                                     (h64 ? "-64" : "-32");
            write_file(stem + "-le" + ext,
                       vtk_xml(a, polydata, e, false, h64, "LittleEndian"));
            write_file(stem + "-be" + ext,
                       vtk_xml(a, polydata, e, true, h64, "BigEndian"));
            const MeshData le = read(stem + "-le" + ext, polydata);
            const MeshData be = read(stem + "-be" + ext, polydata);
            deallog << "  " << encoding_name(e) << ", "
                    << (h64 ? "UInt64" : "UInt32") << " header (" << be.format
                    << "): " << be.nodes.size() << " nodes, "
                    << (polydata ? be.triangles.size() : be.tetrahedra.size())
                    << (polydata ? " triangles" : " tetrahedra")
                    << "; little-endian is the beam: "
                    << ok(identical(le, beam, polydata))
                    << ", big-endian identical to it: "
                    << ok(identical(be, le, polydata)) << std::endl;
          }
      // Ascii is text: the declared byte order does not matter.
      for (const std::string order : {"BigEndian", "Middle"})
        {
          const std::string file = "beam-ascii-" + order + ext;
          write_file(
            file, vtk_xml(a, polydata, Encoding::ascii, false, false, order));
          const MeshData d = read(file, polydata);
          deallog << "  ascii, byte_order=\"" << order << "\" (" << d.format
                  << "): " << d.nodes.size() << " nodes, identical to the "
                  << "beam: " << ok(identical(d, beam, polydata)) << std::endl;
        }
    }

  // Truncated big-endian arrays: the sizes in the messages are the header's
  // own (types: 80 bytes), so a header read in the wrong byte order would
  // show here as a huge number.
  const Arrays tets = arrays_of(beam, false);
  refused(
    "big-endian appended raw array cut short",
    "cut-raw.vtu",
    vtk_xml(tets, false, Encoding::appended_raw, true, false, "BigEndian", 30));
  refused("big-endian inline base64 array cut short (UInt64 header)",
          "cut-base64.vtu",
          vtk_xml(tets, false, Encoding::base64, true, true, "BigEndian", 40));
  refused(
    "big-endian zlib block cut short (UInt64 header)",
    "cut-zlib.vtu",
    vtk_xml(
      tets, false, Encoding::appended_raw_zlib, true, true, "BigEndian", 10));
  refused("big-endian VTP polygons cut short",
          "cut-raw.vtp",
          vtk_xml(arrays_of(beam, true),
                  true,
                  Encoding::appended_raw,
                  true,
                  false,
                  "BigEndian",
                  100),
          true);
  refused("binary data under byte_order=\"Middle\"",
          "middle.vtu",
          vtk_xml(tets, false, Encoding::base64, false, false, "Middle"));
}
