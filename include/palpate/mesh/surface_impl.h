// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#ifndef palpate_mesh_surface_impl_h
#define palpate_mesh_surface_impl_h

// Not an interface: reading and writing organ surfaces (surface.h), shared
// by its source files, one job each:
//   surface.cc             the Surface's own measures, subdivide(), and
//                          read_surface(): the format by the extension,
//                          the checks every format passes
//   surface_readers.cc     the STL, OBJ and PLY readers
//   surface_vtk_reader.cc  the legacy VTK POLYDATA reader
//   surface_writer.cc      write_surface() in each format
// Users of surfaces include surface.h, never this header.

#include <palpate/base/exceptions.h>
#include <palpate/mesh/surface.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace palpate
{
  namespace internal
  {
    /** @p s in lower case (ASCII). */
    std::string
    lower(std::string s);

    /** The extension of @p filename, with its dot, in lower case. */
    std::string
    extension_of(const std::string &filename);

    /** The problem @p problem in @p filename (at @p line if not 0). */
    InputError
    bad(const std::string &filename,
        const unsigned int line,
        const std::string &problem,
        const std::string &fix);

    /** What to do about a surface file whose contents make no sense. */
    inline const char *const damaged = "the file is damaged or truncated; "
                                       "export the surface again.";

    /** The whole of @p filename, its size checked first. */
    std::string
    contents(const std::string &filename);

    /** Bytes of a binary file, read in order, checked against its end. */
    class Bytes
    {
    public:
      Bytes(const std::string &filename,
            const std::string &data,
            std::size_t        pos,
            const bool         big_endian)
        : filename(filename)
        , data(data)
        , pos(pos)
        , big_endian(big_endian)
      {}

      template <typename T>
      T
      get()
      {
        if (pos + sizeof(T) > data.size())
          throw bad(filename,
                    0,
                    "the binary data end early (at byte " +
                      std::to_string(pos) + " of " +
                      std::to_string(data.size()) + ")",
                    damaged);
        unsigned char b[sizeof(T)];
        std::memcpy(b, data.data() + pos, sizeof(T));
        if (big_endian)
          std::reverse(b, b + sizeof(T));
        T x;
        std::memcpy(&x, b, sizeof(T));
        pos += sizeof(T);
        return x;
      }

      /** A value of the PLY/VTK type called @p type, as a double. */
      double
      get_typed(const std::string &type);

      std::size_t
      position() const
      {
        return pos;
      }

    private:
      const std::string &filename;
      const std::string &data;
      std::size_t        pos;
      const bool         big_endian;
    };

    /** Check a vertex index and add the polygon as a fan of triangles. */
    void
    add_polygon(Surface                      &s,
                const std::vector<long long> &polygon,
                const std::string            &filename,
                const unsigned int            line);

    /**
     * STL keeps no shared vertices: each triangle has its own three. The
     * repair merges coincident vertices afterwards.
     */
    Surface
    read_stl(const std::string &filename);

    /** A Wavefront OBJ file's faces. */
    Surface
    read_obj(const std::string &filename);

    /** A PLY file's vertex and face elements, ASCII or binary. */
    Surface
    read_ply(const std::string &filename);

    /** A legacy VTK file's POLYDATA surface. */
    Surface
    read_vtk_polydata(const std::string &filename);
  } // namespace internal
} // namespace palpate

#endif
