#include "vnsba/render/png.hpp"

#include <cairo.h>
#include <librsvg/rsvg.h>

#include <cmath>
#include <memory>

#include "vnsba/render/svg.hpp"

namespace vnsba::render {
namespace {

core::Status failure(std::string message) {
  return core::Status::error(core::StatusCode::kInvalidRequest, std::move(message));
}

// GError's message, freed.
std::string take_message(GError* error, const char* fallback) {
  if (error == nullptr) return fallback;
  std::string message = error->message != nullptr ? error->message : fallback;
  g_error_free(error);
  return message;
}

struct HandleDeleter {
  void operator()(RsvgHandle* h) const { g_object_unref(h); }
};
struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

cairo_status_t append_bytes(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

core::Expected<std::string> svg_to_png(std::string_view svg) {
  GError* error = nullptr;
  std::unique_ptr<RsvgHandle, HandleDeleter> handle(
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &error));
  if (!handle) return failure("not a readable SVG: " + take_message(error, "librsvg refused it"));
  // Pixels: the width and height attributes (user units are CSS px at librsvg's 96 dpi), else
  // the viewBox.
  double width = 0.0, height = 0.0;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(handle.get(), &width, &height)) {
    gboolean has_width = FALSE, has_height = FALSE, has_viewbox = FALSE;
    RsvgLength w, h;
    RsvgRectangle viewbox;
    rsvg_handle_get_intrinsic_dimensions(handle.get(), &has_width, &w, &has_height, &h,
                                         &has_viewbox, &viewbox);
    if (!has_viewbox) return failure("the SVG has neither a size in pixels nor a viewBox");
    width = viewbox.width;
    height = viewbox.height;
  }
  if (!(width >= 1.0 && height >= 1.0) || !(width * height <= kMaxPngPixels))
    return failure("the SVG is " + std::to_string(width) + " x " + std::to_string(height) +
                   " pixels; a PNG must be at least 1 x 1 and at most " +
                   std::to_string(static_cast<long long>(kMaxPngPixels)) + " pixels");
  const int pixels_w = static_cast<int>(std::ceil(width));
  const int pixels_h = static_cast<int>(std::ceil(height));
  std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, pixels_w, pixels_h));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS)
    return failure(std::string("cairo could not make the image: ") +
                   cairo_status_to_string(cairo_surface_status(surface.get())));
  std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
  const RsvgRectangle viewport{0.0, 0.0, width, height};
  if (!rsvg_handle_render_document(handle.get(), cr.get(), &viewport, &error))
    return failure("librsvg could not draw the SVG: " +
                   take_message(error, "rsvg_handle_render_document failed"));
  cairo_surface_flush(surface.get());
  std::string png;
  const cairo_status_t written =
      cairo_surface_write_to_png_stream(surface.get(), append_bytes, &png);
  if (written != CAIRO_STATUS_SUCCESS)
    return failure(std::string("cairo could not encode the PNG: ") +
                   cairo_status_to_string(written));
  return png;
}

core::Status write_png_file(const std::string& path, std::string_view svg) {
  auto png = svg_to_png(svg);
  if (!png) return failure(path + ": " + png.error().message);
  const core::Status written = write_text_file(path, *png);
  if (!written.is_ok()) return failure(written.message);  // names the path
  return core::Status::ok();
}

}  // namespace vnsba::render
