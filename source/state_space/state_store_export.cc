// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The ParaView export of a store (StateStore::export_vtk): its states on
// the grid as a legacy VTK file. Apart from the rest because it is output
// for a person to look at, not part of keeping states, and reads the store
// only through read_all().

#include <palpate/base/exceptions.h>
#include <palpate/state_space/state_grid.h>
#include <palpate/state_space/state_store.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <vector>

namespace palpate
{
  void
  StateStore::export_vtk(const StateGrid   &grid,
                         const std::string &filename) const
  {
    unsigned int               damaged = 0;
    const auto                 all     = read_all(damaged);
    const auto                 n       = grid.size();
    std::vector<const State *> at(n, nullptr);
    for (const auto &[point, state] : all)
      if (point < n)
        at[point] = &state;
    std::ofstream out(filename);
    if (!out)
      throw OutputError("cannot write '" + filename + "'");
    out.precision(9);
    const unsigned int side = 2 * grid.half_width() + 1;
    const double       h = grid.spacing(), o = -h * grid.half_width();
    out << "# vtk DataFile Version 3.0\npalpate state space of " << file()
        << "\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS " << side << ' '
        << side << ' ' << side << "\nORIGIN " << o << ' ' << o << ' ' << o
        << "\nSPACING " << h << ' ' << h << ' ' << h << "\nPOINT_DATA " << n
        << "\n";
    // VTK orders points x fastest: the grid's linear number may not, so go
    // by index.
    const auto point_at =
      [&](const unsigned int i, const unsigned int j, const unsigned int k) {
        const int w = grid.half_width();
        return grid.linear(GridIndex{{int(i) - w, int(j) - w, int(k) - w}});
      };
    const auto each = [&](const auto &write) {
      for (unsigned int k = 0; k < side; ++k)
        for (unsigned int j = 0; j < side; ++j)
          for (unsigned int i = 0; i < side; ++i)
            write(at[point_at(i, j, k)]);
    };
    out << "VECTORS force double\n";
    each([&](const State *s) {
      const bool f = s != nullptr && s->converged;
      out << (f ? s->force[0] : 0.) << ' ' << (f ? s->force[1] : 0.) << ' '
          << (f ? s->force[2] : 0.) << '\n';
    });
    out << "SCALARS force_magnitude double 1\nLOOKUP_TABLE default\n";
    each([&](const State *s) {
      out << (s != nullptr && s->converged ? Utilities::norm(s->force) : 0.)
          << '\n';
    });
    out << "SCALARS status int 1\nLOOKUP_TABLE default\n";
    each([&](const State *s) {
      out << (s == nullptr ? -1 :
              s->converged ? 0 :
                             1 + static_cast<int>(s->status))
          << '\n';
    });
    out << "TENSORS stiffness double\n";
    each([&](const State *s) {
      for (unsigned int r = 0; r < 3; ++r)
        out << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r] : 0.)
            << ' '
            << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r + 1] : 0.)
            << ' '
            << (s != nullptr && s->has_stiffness ? s->stiffness[3 * r + 2] : 0.)
            << '\n';
    });
    out.flush();
    if (!out)
      throw OutputError("writing '" + filename + "' failed (" +
                        std::strerror(errno) + ")");
  }
} // namespace palpate
