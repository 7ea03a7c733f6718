// The OpenVDB writer behind ilf::write_vdb (internal to ilf/): ilf/vdb_export.cpp provides it, from
// the "vdb" plugin in the iblkit command (OpenVDB brings Boost, Blosc and more with it).
#pragma once
#include <string>

#include "iblkit/core/plugin.h"
#include "iblkit/ilf/shgrid.h"

namespace ibl::ilf::detail {

struct VdbWriter {
  void (*write)(const std::string& path, const SHGrid& g);
};
extern plugin::Provided<VdbWriter> vdb_writer;

}  // namespace ibl::ilf::detail
