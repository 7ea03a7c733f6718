// The CPU reference renderer: exact visibility (a z-buffer rasteriser sampling pixel centres, the
// same coverage rule GL uses), per-pixel shading with render/shading.h, and shadows from Embree
// shadow rays — no shadow-map approximations. Deterministic.
#pragma once
#include "iblkit/core/progress.h"
#include "iblkit/render/frame.h"

namespace ibl::render {

RenderResult render_cpu(const FrameDesc& desc, const ProgressFn& progress = {});

}  // namespace ibl::render
