// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_readers_vtk_xml_data_h
#define palpate_mesh_readers_vtk_xml_data_h

#include <palpate/base/exceptions.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace palpate
{
  namespace mesh_readers
  {
    /** The value of attribute @p name in the XML tag @p tag, "" if it has
     * none. */
    std::string
    attribute(const std::string &tag, const std::string &name);

    /** Compact copy of @p text without white space. */
    std::string
    strip_space(const std::string &text);

    /** The line (from 1) on which position @p at of @p text lies. */
    unsigned int
    line_at(const std::string &text, const std::size_t at);

    /**
     * A count given as an XML attribute (NumberOfPoints, NumberOfCells, an
     * appended array's offset) @p name of the tag @p tag of @p element, at
     * @p line of @p filename: a whole number, 0 or more. It is checked
     * digit by digit: std::stol would read "-5" as -5 and "12abc" as 12,
     * and a missing or garbled count must not become an empty mesh.
     */
    std::uint64_t
    count_attribute(const std::string &filename,
                    const unsigned int line,
                    const std::string &element,
                    const std::string &tag,
                    const std::string &name);

    /** Whether this machine stores numbers little-endian (x86, ARM). */
    bool
    host_is_little_endian();

    /** How a VTK XML file stores its binary arrays, and where the array
     * being read is, for data_array_values(). */
    struct VtuContext
    {
      /** The file, for messages. */
      std::string filename;
      /** Array headers are UInt64, not UInt32. */
      bool header_64 = false;
      /** The arrays are zlib-compressed (vtkZLibDataCompressor). */
      bool compressed = false;
      /**
       * The file's byte order differs from this machine's: every binary
       * value, the UInt32/UInt64 sizes of the array headers included, is
       * byte-swapped as it is read. Ascii arrays are text and need
       * nothing, whatever the file declares.
       */
      bool swap_bytes = false;
      /** The byte_order attribute, if it is neither LittleEndian nor
       * BigEndian: refused when a binary array needs it, and only then. */
      std::string unknown_byte_order;
      /** The line of the <VTKFile> tag, which declares the byte order. */
      unsigned int file_tag_line = 1;
      /** The <AppendedData> section: raw bytes, or base64 text. */
      std::string appended;
      /** The appended data is base64 text. */
      bool appended_base64 = false;
      /** The line of the <DataArray> being read, for messages. */
      unsigned int line = 0;

      /** Bytes per header value: UInt32 or UInt64. */
      std::size_t
      header_size() const
      {
        return header_64 ? 8 : 4;
      }

      /** The error for a binary array that does not hold what it says. */
      InputError
      damaged(const std::string &name, const std::string &problem) const
      {
        return InputError(filename,
                          line,
                          "DataArray " + name,
                          problem,
                          "the file is damaged or truncated; write it again.");
      }
    };

    /**
     * The values of one <DataArray> (the tag @p tag, the text @p content
     * between it and its end tag), whatever its format, as doubles: ascii,
     * base64 binary or appended data (raw or base64), each raw or
     * zlib-compressed, byte-swapped if the file's byte order is not this
     * machine's. Every number in an array's header comes from the file and
     * is checked against the bytes that are there.
     */
    std::vector<double>
    data_array_values(const VtuContext  &ctx,
                      const std::string &tag,
                      const std::string &content);
  } // namespace mesh_readers
} // namespace palpate

#endif
