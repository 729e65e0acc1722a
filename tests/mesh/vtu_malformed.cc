// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// Malformed .vtu files are refused with an InputError that names the file
// and says what is wrong, never a crash, an out-of-bounds read or a
// silently empty mesh: appended data cut short, array headers (byte counts,
// block tables, block sizes) that promise more than the file holds, offsets
// past the data, a NumberOfPoints or NumberOfCells that is not a count, a
// tag cut in half, and paths that cannot be read (a directory, a symbolic
// link to itself). A valid file of the same make is read first, so that
// every refusal is due to the one defect it adds.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/mesh_file.h>

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>

#include "../tests.h"

namespace
{
  using Bytes = std::vector<unsigned char>;

  template <typename T>
  Bytes
  raw(const std::vector<T> &v)
  {
    Bytes b(v.size() * sizeof(T));
    std::memcpy(b.data(), v.data(), b.size());
    return b;
  }

  Bytes
  concat(const Bytes &a, const Bytes &b)
  {
    Bytes c = a;
    c.insert(c.end(), b.begin(), b.end());
    return c;
  }

  /** The four arrays of one tetrahedron: points, connectivity, offsets,
   * types. */
  std::vector<Bytes>
  tetrahedron_arrays()
  {
    return {raw(std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}),
            raw(std::vector<std::int32_t>{0, 1, 2, 3}),
            raw(std::vector<std::int32_t>{4}),
            raw(std::vector<std::uint8_t>{10})};
  }

  /** An uncompressed block: UInt32 byte count, then the bytes. */
  Bytes
  plain_block(const Bytes &data)
  {
    return concat(raw(std::vector<std::uint32_t>{
                    static_cast<std::uint32_t>(data.size())}),
                  data);
  }

  /** A zlib block as VTK writes it: a header (number of blocks, block
   * size, size of the last block, compressed sizes), then the data. */
  Bytes
  zlib_block(const Bytes &data)
  {
    uLongf size = compressBound(data.size());
    Bytes  packed(size);
    compress(packed.data(), &size, data.data(), data.size());
    packed.resize(size);
    const auto n = static_cast<std::uint32_t>(data.size());
    return concat(raw(std::vector<std::uint32_t>{
                    1, n, n, static_cast<std::uint32_t>(size)}),
                  packed);
  }

  /** Overwrite the UInt32 at byte @p at of @p block with @p value. */
  Bytes
  patched(Bytes block, const std::size_t at, const std::uint32_t value)
  {
    std::memcpy(block.data() + at, &value, 4);
    return block;
  }

  /**
   * A .vtu file with raw appended data made of @p blocks (one per array,
   * header included). @p piece are the attributes of <Piece>; @p offsets,
   * if given, replace the offset attributes the blocks would have.
   */
  std::string
  appended_vtu(const std::vector<Bytes>       &blocks,
               const bool                      zlib    = false,
               const std::string              &piece   = "NumberOfPoints=\"4\" "
                                                         "NumberOfCells=\"1\"",
               const std::vector<std::string> &offsets = {})
  {
    const char *types[] = {"Float64", "Int32", "Int32", "UInt8"};
    const char *names[] = {"", "connectivity", "offsets", "types"};
    std::string s =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" "
      "version=\"0.1\" byte_order=\"LittleEndian\" header_type=\"UInt32\"" +
      std::string(zlib ? " compressor=\"vtkZLibDataCompressor\"" : "") +
      ">\n<UnstructuredGrid>\n<Piece " + piece + ">\n";
    std::string data;
    for (unsigned int a = 0; a < 4; ++a)
      {
        if (a == 0)
          s += "<Points>\n";
        if (a == 1)
          s += "<Cells>\n";
        s += std::string("<DataArray type=\"") + types[a] + "\"" +
             (a == 0 ? " NumberOfComponents=\"3\"" :
                       std::string(" Name=\"") + names[a] + "\"") +
             " format=\"appended\" offset=\"" +
             (offsets.empty() ? std::to_string(data.size()) : offsets[a]) +
             "\"/>\n";
        data.append(blocks[a].begin(), blocks[a].end());
        if (a == 0)
          s += "</Points>\n";
        if (a == 3)
          s += "</Cells>\n";
      }
    return s + "</Piece>\n</UnstructuredGrid>\n" +
           "<AppendedData encoding=\"raw\">\n_" + data +
           "\n</AppendedData>\n</VTKFile>\n";
  }

  std::vector<Bytes>
  plain_blocks()
  {
    std::vector<Bytes> blocks;
    for (const auto &a : tetrahedron_arrays())
      blocks.push_back(plain_block(a));
    return blocks;
  }

  std::vector<Bytes>
  zlib_blocks()
  {
    std::vector<Bytes> blocks;
    for (const auto &a : tetrahedron_arrays())
      blocks.push_back(zlib_block(a));
    return blocks;
  }

  /** Read @p file and say what happened. */
  void
  read(const std::string &what, const std::string &file)
  {
    try
      {
        const palpate::MeshData data = palpate::read_mesh_file(file);
        deallog << what << ": accepted, " << data.nodes.size() << " nodes, "
                << data.tetrahedra.size() << " tetrahedra" << std::endl;
      }
    catch (const palpate::InputError &e)
      {
        deallog << what << ": refused" << std::endl << e.what() << std::endl;
      }
    catch (const std::exception &e)
      {
        deallog << what << ": NOT AN InputError: " << e.what() << std::endl;
      }
  }

  void
  check(const std::string &what,
        const std::string &file,
        const std::string &text)
  {
    write_file(file, text);
    read(what, file);
  }
} // namespace

int
main(int argc, char **argv)
{
  palpate::Environment env(argc, argv);
  initlog();

  // The valid files everything below breaks.
  const std::string plain = appended_vtu(plain_blocks());
  check("a valid raw appended file", "valid.vtu", plain);
  check("a valid zlib raw appended file",
        "valid-zlib.vtu",
        appended_vtu(zlib_blocks(), true));

  // Truncated files: cut in the appended data, and inside a tag.
  check("appended data cut short",
        "truncated.vtu",
        plain.substr(0, plain.find("\n_") + 62));
  check("a file cut inside a <DataArray> tag",
        "cut-tag.vtu",
        plain.substr(0, plain.find("<DataArray") + 20));

  // Headers that promise more than the file holds.
  {
    auto blocks = plain_blocks();
    blocks[0]   = patched(blocks[0], 0, 4000);
    check("an uncompressed byte count larger than the data",
          "long-count.vtu",
          appended_vtu(blocks));
    blocks[0] = patched(blocks[0], 0, 0xfffffff0u);
    check("a huge uncompressed byte count",
          "huge-count.vtu",
          appended_vtu(blocks));
  }
  {
    auto blocks = zlib_blocks();
    blocks[0]   = patched(blocks[0], 0, 1000);
    check("a compressed header larger than the data (1000 blocks)",
          "long-header.vtu",
          appended_vtu(blocks, true));
    blocks[0] = patched(blocks[0], 0, 0xffffffffu);
    check("a huge compressed header (2^32-1 blocks)",
          "huge-header.vtu",
          appended_vtu(blocks, true));
  }
  {
    auto blocks = zlib_blocks();
    blocks[0]   = patched(blocks[0], 4, 0xfffffff0u);
    blocks[0]   = patched(blocks[0], 8, 0xfffffff0u);
    check("a huge uncompressed block size",
          "huge-block.vtu",
          appended_vtu(blocks, true));
    blocks    = zlib_blocks();
    blocks[0] = patched(blocks[0], 12, 0xfffffff0u);
    check("a huge compressed block size",
          "huge-compressed.vtu",
          appended_vtu(blocks, true));
  }
  check("an offset past the appended data",
        "far-offset.vtu",
        appended_vtu(plain_blocks(),
                     false,
                     "NumberOfPoints=\"4\" NumberOfCells=\"1\"",
                     {"0", "99999999999", "0", "0"}));
  check("an offset that is not a number",
        "bad-offset.vtu",
        appended_vtu(plain_blocks(),
                     false,
                     "NumberOfPoints=\"4\" NumberOfCells=\"1\"",
                     {"0", "abc", "0", "0"}));

  // Counts that are not counts.
  check("NumberOfPoints=\"abc\"",
        "points-abc.vtu",
        appended_vtu(plain_blocks(),
                     false,
                     "NumberOfPoints=\"abc\" NumberOfCells=\"1\""));
  check("NumberOfPoints=\"-5\"",
        "points-negative.vtu",
        appended_vtu(plain_blocks(),
                     false,
                     "NumberOfPoints=\"-5\" NumberOfCells=\"1\""));
  check("no NumberOfPoints",
        "points-missing.vtu",
        appended_vtu(plain_blocks(), false, "NumberOfCells=\"1\""));
  check("NumberOfCells=\"1.5\"",
        "cells-fraction.vtu",
        appended_vtu(plain_blocks(),
                     false,
                     "NumberOfPoints=\"4\" NumberOfCells=\"1.5\""));

  // Paths that exist but cannot be read.
  std::filesystem::remove_all("directory.vtu");
  std::filesystem::create_directory("directory.vtu");
  read("a directory given as the mesh file", "directory.vtu");
  std::filesystem::remove("loop.vtu");
  std::filesystem::create_symlink("loop.vtu", "loop.vtu");
  read("a symbolic link to itself", "loop.vtu");
  write_file("empty.vtu", "");
  read("an empty file", "empty.vtu");
}
