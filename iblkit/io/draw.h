// Drawing into images for pictures a person looks at: text (through OpenImageIO's FreeType
// renderer with the DejaVu font from Debian's fonts-dejavu-core), lines, markers, contact sheets.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "iblkit/core/image.h"

namespace ibl::io {

// Draws text with its baseline-left at (x, y), `size` pixels tall, in colour rgb. Returns false
// (and draws nothing) when no font is available.
bool draw_text(Image& img, int x, int y, const std::string& text, int size, Vec3 rgb);
// A line of width ~1 px (Xiaolin Wu style anti-aliasing blended over the image).
void draw_line(Image& img, double x0, double y0, double x1, double y1, Vec3 rgb, double width = 1.0);
// A filled disc marker of radius r.
void draw_disc(Image& img, double cx, double cy, double r, Vec3 rgb);
// A filled rectangle.
void fill_rect(Image& img, int x0, int y0, int x1, int y1, Vec3 rgb);

// Lays out pictures (already tone mapped, RGB in [0,1]) in a grid with a caption under each, every
// picture scaled to fit cell_width × cell_height (aspect kept). Background dark grey.
Image contact_sheet(const std::vector<std::pair<std::string, Image>>& pictures, int columns, int cell_width,
                    int cell_height, const std::string& title = {});

// Box-filtered resize of any image (area average when shrinking, bilinear when enlarging).
Image resize(const Image& img, int width, int height);

}  // namespace ibl::io
