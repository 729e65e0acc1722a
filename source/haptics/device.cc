// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

#include <palpate/base/plugins.templates.h>
#include <palpate/haptics/device.h>
#include <palpate/scene/scene.h>

namespace palpate
{
  std::unique_ptr<Device>
  Device::create(const Scene &scene)
  {
    const auto &h   = scene.parameters.haptics;
    const auto  own = h.own.find(h.device);
    try
      {
        return DeviceRegistry::create(h.device,
                                      own == h.own.end() ? Plugins::Entries() :
                                                           own->second,
                                      scene);
      }
    catch (const Plugins::EntryError &e)
      {
        throw scene.error("Haptics/" + h.device + "/" + e.entry,
                          e.problem,
                          e.fix);
      }
  }



  template class Plugins::Registry<Device, Scene>;
} // namespace palpate
