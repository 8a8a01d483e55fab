// Saving a widget as a picture: PNG (what the screen shows, grab()) or SVG
// (vectors, drawn by `paint_svg` onto a white page of the widget's size),
// chosen by the file's suffix and written atomically (QSaveFile).
#pragma once

#include <QString>
#include <functional>

class QPainter;
class QSize;
class QWidget;

namespace codyna::gui {

// false with *error ("PATH: reason") for an unknown suffix or a failed render/write
bool save_widget_image(QWidget* widget, const QString& path, const QString& title,
                       const std::function<void(QPainter&)>& paint_svg, QString* error = nullptr);

// a picture of `size` pixels drawn by `paint` (onto a white page of that size) into a .png
// (raster, 96 dpi) or a .svg (vectors), by suffix, written atomically; false with *error
bool save_painted_image(const QString& path, const QSize& size, const QString& title,
                        const std::function<void(QPainter&)>& paint, QString* error = nullptr);

// true when `path` ends in .png or .svg (so a caller can check before preparing a render)
bool is_image_path(const QString& path);

}  // namespace codyna::gui
