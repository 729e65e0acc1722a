// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The arrays of a VTK XML file (.vtu, .vtp): ascii, base64 or appended
// binary data, raw or zlib-compressed, in either byte order.

#include <palpate/base/utilities.h>
#include <palpate/mesh/readers/vtk_xml_data.h>

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <regex>
#include <sstream>

namespace palpate
{
  namespace mesh_readers
  {
    namespace
    {
      std::vector<unsigned char>
      base64_decode(const std::string &text, std::size_t begin, std::size_t end)
      {
        static const std::string alphabet =
          "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        std::vector<unsigned char> out;
        unsigned int               buffer = 0;
        int                        bits   = 0;
        for (std::size_t i = begin; i < end; ++i)
          {
            const char c = text[i];
            if (c == '=')
              break;
            const auto k = alphabet.find(c);
            if (k == std::string::npos)
              continue; // white space
            buffer = (buffer << 6) | static_cast<unsigned int>(k);
            bits += 6;
            if (bits >= 8)
              {
                bits -= 8;
                out.push_back(
                  static_cast<unsigned char>((buffer >> bits) & 0xff));
              }
          }
        return out;
      }

      /** Reverse the @p size bytes at @p p: one value to the other byte
       * order. */
      void
      reverse_bytes(unsigned char *p, const std::size_t size)
      {
        std::reverse(p, p + size);
      }

      /**
       * Value @p k of a binary array's header. Every number in a header
       * comes from the file, so each read is checked against the bytes that
       * are there.
       */
      std::uint64_t
      header_value(const VtuContext                 &ctx,
                   const std::vector<unsigned char> &header,
                   const std::uint64_t               k,
                   const std::string                &name)
      {
        const std::size_t hs = ctx.header_size();
        if (k >= header.size() / hs)
          throw ctx.damaged(name, "the array's header is cut short");
        // The sizes are in the file's byte order, like the data.
        unsigned char value[8];
        std::memcpy(value, header.data() + k * hs, hs);
        if (ctx.swap_bytes)
          reverse_bytes(value, hs);
        if (ctx.header_64)
          {
            std::uint64_t v;
            std::memcpy(&v, value, 8);
            return v;
          }
        std::uint32_t v;
        std::memcpy(&v, value, 4);
        return v;
      }

      /**
       * The data bytes of one binary array, given its decoded VTK header
       * (byte count, or block table if zlib-compressed) and the decoded bytes
       * that follow it. Every size in the header is checked against the
       * bytes that follow before anything is read or allocated.
       */
      std::vector<unsigned char>
      decode_block_data(const VtuContext                 &ctx,
                        const std::vector<unsigned char> &header,
                        const std::vector<unsigned char> &payload,
                        const std::string                &name)
      {
        if (!ctx.compressed)
          {
            const std::uint64_t n = header_value(ctx, header, 0, name);
            if (n > payload.size())
              throw ctx.damaged(name,
                                "the array's header says it holds " +
                                  std::to_string(n) + " bytes, but only " +
                                  std::to_string(payload.size()) +
                                  " follow it");
            return std::vector<unsigned char>(payload.begin(),
                                              payload.begin() + n);
          }
        // zlib's deflate packs at most 1032 bytes into one (zlib's technical
        // details): a block that claims more is damaged, and this bounds what
        // a damaged header can make us allocate.
        constexpr std::uint64_t max_deflate_ratio = 1032;
        const std::uint64_t     n_blocks = header_value(ctx, header, 0, name);
        const std::uint64_t     block    = header_value(ctx, header, 1, name);
        const std::uint64_t     last     = header_value(ctx, header, 2, name);
        std::vector<unsigned char> out;
        std::size_t                offset = 0;
        for (std::uint64_t b = 0; b < n_blocks; ++b)
          {
            const std::uint64_t csize = header_value(ctx, header, 3 + b, name);
            const std::uint64_t size =
              (b + 1 == n_blocks && last != 0) ? last : block;
            if (csize > payload.size() - offset)
              throw ctx.damaged(name,
                                "compressed block " + std::to_string(b) +
                                  " has " + std::to_string(csize) +
                                  " bytes by the array's header, but only " +
                                  std::to_string(payload.size() - offset) +
                                  " are left");
            if (size > max_deflate_ratio * csize)
              throw ctx.damaged(name,
                                "compressed block " + std::to_string(b) +
                                  " is said to unpack to " +
                                  std::to_string(size) +
                                  " bytes, more than zlib can pack into " +
                                  std::to_string(csize) + " bytes");
            const std::size_t start = out.size();
            out.resize(start + size);
            uLongf unpacked = size;
            if (uncompress(out.data() + start,
                           &unpacked,
                           payload.data() + offset,
                           csize) != Z_OK)
              throw ctx.damaged(name,
                                "a zlib-compressed block cannot be "
                                "decompressed");
            out.resize(start + unpacked);
            offset += csize;
          }
        return out;
      }

      /**
       * Header length in bytes, given the first header value(s) and the
       * number of bytes @p available from the header's start to the end of
       * the data. A compressed array's header lists its blocks; a damaged
       * block count (up to 2^64 - 1) is refused before it is multiplied.
       */
      std::size_t
      header_length(const VtuContext                 &ctx,
                    const std::vector<unsigned char> &first,
                    const std::size_t                 available,
                    const std::string                &name)
      {
        const std::size_t hs = ctx.header_size();
        if (!ctx.compressed)
          return hs;
        const std::uint64_t n_blocks = header_value(ctx, first, 0, name);
        if (available / hs < 3 || n_blocks > available / hs - 3)
          throw ctx.damaged(name,
                            "the array's header lists " +
                              std::to_string(n_blocks) +
                              " compressed blocks, but the file holds only " +
                              std::to_string(available) +
                              " bytes from there on, too few for even their "
                              "sizes");
        return (3 + n_blocks) * hs;
      }

      /** The raw bytes of a binary (inline base64) or appended data array. */
      std::vector<unsigned char>
      binary_array_bytes(const VtuContext  &ctx,
                         const std::string &encoded, // inline: base64 text
                         const bool         is_inline,
                         const std::size_t  appended_offset,
                         const std::string &name)
      {
        const std::size_t hs = ctx.header_size();
        if (is_inline || ctx.appended_base64)
          {
            const std::string &text  = is_inline ? encoded : ctx.appended;
            const std::size_t  start = is_inline ? 0 : appended_offset;
            if (!is_inline && start >= text.size())
              throw ctx.damaged(
                name,
                "the array's offset " + std::to_string(start) +
                  " points past the end of the appended data (" +
                  std::to_string(text.size()) + " characters)");
            // At most 3 bytes per 4 base64 characters from here on.
            const std::size_t available =
              start < text.size() ? (text.size() - start + 3) / 4 * 3 : 0;
            // VTK encodes header and data separately when compressing, and
            // writers differ otherwise: try "separately" first, then
            // "together".
            const std::size_t first_chars = 4 * ((hs + 2) / 3);
            auto              first =
              base64_decode(text,
                            start,
                            std::min(text.size(), start + first_chars));
            if (first.size() < hs)
              throw ctx.damaged(name, "the binary array is empty");
            const std::size_t hl = header_length(ctx, first, available, name);
            const std::size_t header_chars = 4 * ((hl + 2) / 3);
            // Appended base64 arrays follow each other; decoding stops at
            // the padding of this array's data, and the header says how many
            // bytes are this array's.
            const std::size_t end = text.size();
            const auto        header =
              base64_decode(text,
                            start,
                            std::min(text.size(), start + header_chars));
            if (header.size() >= hl)
              {
                const auto payload =
                  base64_decode(text, start + header_chars, end);
                try
                  {
                    auto bytes = decode_block_data(ctx, header, payload, name);
                    return bytes;
                  }
                catch (const InputError &)
                  {
                    // fall through to "together"
                  }
              }
            const auto all = base64_decode(text, start, end);
            if (all.size() < hl)
              throw ctx.damaged(name,
                                "the binary array is shorter than its header");
            return decode_block_data(
              ctx,
              std::vector<unsigned char>(all.begin(), all.begin() + hl),
              std::vector<unsigned char>(all.begin() + hl, all.end()),
              name);
          }
        // Raw appended data: the offset and every length come from the file
        // and are checked against the bytes after the '_' marker.
        const std::size_t size = ctx.appended.size();
        if (appended_offset >= size)
          throw ctx.damaged(name,
                            "the array's offset " +
                              std::to_string(appended_offset) +
                              " points past the end of the appended data (" +
                              std::to_string(size) + " bytes)");
        const std::size_t left = size - appended_offset;
        const auto       *p =
          reinterpret_cast<const unsigned char *>(ctx.appended.data()) +
          appended_offset;
        if (left < hs)
          throw ctx.damaged(name,
                            "the appended data end inside the array's header");
        const std::vector<unsigned char> first(p, p + hs);
        const std::size_t hl = header_length(ctx, first, left, name);
        if (hl > left)
          throw ctx.damaged(name,
                            "the appended data end inside the array's header");
        return decode_block_data(ctx,
                                 std::vector<unsigned char>(p, p + hl),
                                 std::vector<unsigned char>(p + hl, p + left),
                                 name);
      }

      /** The values of type @p T in @p bytes, byte-swapped first if
       * @p swap (the file's byte order is not this machine's). */
      template <typename T>
      std::vector<double>
      bytes_to_doubles(const std::vector<unsigned char> &bytes, const bool swap)
      {
        std::vector<double> v(bytes.size() / sizeof(T));
        for (std::size_t i = 0; i < v.size(); ++i)
          {
            unsigned char b[sizeof(T)];
            std::memcpy(b, bytes.data() + i * sizeof(T), sizeof(T));
            if (swap)
              reverse_bytes(b, sizeof(T));
            T x;
            std::memcpy(&x, b, sizeof(T));
            v[i] = static_cast<double>(x);
          }
        return v;
      }
    } // namespace

    std::string
    attribute(const std::string &tag, const std::string &name)
    {
      std::smatch m;
      if (std::regex_search(tag,
                            m,
                            std::regex("\\b" + name + "\\s*=\\s*\"([^\"]*)\"")))
        return m[1].str();
      return "";
    }

    std::string
    strip_space(const std::string &text)
    {
      std::string s;
      for (const char c : text)
        if (!std::isspace(static_cast<unsigned char>(c)))
          s += c;
      return s;
    }

    unsigned int
    line_at(const std::string &text, const std::size_t at)
    {
      return 1 + std::count(text.begin(),
                            text.begin() + std::min(at, text.size()),
                            '\n');
    }

    std::uint64_t
    count_attribute(const std::string &filename,
                    const unsigned int line,
                    const std::string &element,
                    const std::string &tag,
                    const std::string &name)
    {
      const std::string value = Utilities::trim(attribute(tag, name));
      if (value.empty())
        throw InputError(filename,
                         line,
                         element + " " + name,
                         "the " + element + " element does not give its " +
                           name,
                         "the file is damaged or was not written by VTK; "
                         "write it again (ParaView, meshio, deal.II).");
      // 18 digits: far beyond any mesh, and 3 x count stays in 64 bits.
      if (value.size() > 18 ||
          value.find_first_not_of("0123456789") != std::string::npos)
        throw InputError(filename,
                         line,
                         element + " " + name,
                         name + "=\"" + value +
                           "\" is not a count: it must be a whole number, 0 "
                           "or more",
                         "the file is damaged; write it again.");
      return std::stoull(value);
    }

    bool
    host_is_little_endian()
    {
      const std::uint16_t one = 1;
      unsigned char       first;
      std::memcpy(&first, &one, 1);
      return first == 1;
    }

    std::vector<double>
    data_array_values(const VtuContext  &ctx,
                      const std::string &tag,
                      const std::string &content)
    {
      const std::string type   = attribute(tag, "type");
      const std::string format = attribute(tag, "format");
      const std::string name   = attribute(tag, "Name").empty() ?
                                   std::string("Points") :
                                   attribute(tag, "Name");
      if (format == "ascii")
        {
          std::istringstream  s(content);
          std::vector<double> v;
          double              x;
          while (s >> x)
            v.push_back(x);
          if (!s.eof())
            throw InputError(ctx.filename,
                             ctx.line,
                             "DataArray " + name,
                             "the ascii array holds something that is not a "
                             "number",
                             "the file is damaged; write it again.");
          return v;
        }
      if ((format == "binary" || format == "appended") &&
          !ctx.unknown_byte_order.empty())
        throw InputError(ctx.filename,
                         ctx.file_tag_line,
                         "VTKFile byte_order",
                         "byte_order=\"" + ctx.unknown_byte_order +
                           "\" is neither LittleEndian nor BigEndian, so "
                           "the binary data cannot be read",
                         "the file is damaged or was not written by VTK; "
                         "write it again (ParaView, meshio, deal.II).");
      std::vector<unsigned char> bytes;
      if (format == "binary")
        bytes = binary_array_bytes(ctx, strip_space(content), true, 0, name);
      else if (format == "appended")
        bytes = binary_array_bytes(ctx,
                                   "",
                                   false,
                                   count_attribute(ctx.filename,
                                                   ctx.line,
                                                   "DataArray " + name,
                                                   tag,
                                                   "offset"),
                                   name);
      else
        throw InputError(ctx.filename,
                         ctx.line,
                         "DataArray " + name,
                         "unknown format '" + format + "'",
                         "write the file again as ascii or binary.");
      if (type == "Float64")
        return bytes_to_doubles<double>(bytes, ctx.swap_bytes);
      if (type == "Float32")
        return bytes_to_doubles<float>(bytes, ctx.swap_bytes);
      if (type == "Int64")
        return bytes_to_doubles<std::int64_t>(bytes, ctx.swap_bytes);
      if (type == "UInt64")
        return bytes_to_doubles<std::uint64_t>(bytes, ctx.swap_bytes);
      if (type == "Int32")
        return bytes_to_doubles<std::int32_t>(bytes, ctx.swap_bytes);
      if (type == "UInt32")
        return bytes_to_doubles<std::uint32_t>(bytes, ctx.swap_bytes);
      if (type == "Int16")
        return bytes_to_doubles<std::int16_t>(bytes, ctx.swap_bytes);
      if (type == "UInt16")
        return bytes_to_doubles<std::uint16_t>(bytes, ctx.swap_bytes);
      if (type == "Int8")
        return bytes_to_doubles<std::int8_t>(bytes, ctx.swap_bytes);
      if (type == "UInt8")
        return bytes_to_doubles<std::uint8_t>(bytes, ctx.swap_bytes);
      throw InputError(ctx.filename,
                       ctx.line,
                       "DataArray " + name,
                       "unknown data type '" + type + "'",
                       "write the file again with standard VTK types.");
    }
  } // namespace mesh_readers
} // namespace palpate
