#include "gui/image_export.hpp"

#include <QBuffer>
#include <QFileInfo>
#include <QImage>
#include <QPainter>
#include <QPixmap>
#include <QSaveFile>
#include <QSvgGenerator>
#include <QWidget>

namespace codyna::gui {

bool is_image_path(const QString& path) {
  const QString suffix = QFileInfo(path).suffix().toLower();
  return suffix == QLatin1String("png") || suffix == QLatin1String("svg");
}

namespace {

// the bytes into `path` atomically (QSaveFile: the old file stays until the new one is complete)
bool commit(const QByteArray& bytes, const QString& path, QString* error) {
  QSaveFile file(path);
  if (file.open(QIODevice::WriteOnly) && file.write(bytes) == bytes.size() && file.commit()) return true;
  if (error) *error = QStringLiteral("%1: %2").arg(path, file.errorString());
  return false;
}

}  // namespace

bool save_widget_image(QWidget* w, const QString& path, const QString& title,
                       const std::function<void(QPainter&)>& paint_svg, QString* error) {
  if (QFileInfo(path).suffix().toLower() != QLatin1String("png"))
    return save_painted_image(path, w->size(), title, paint_svg, error);  // SVG, or the suffix's error
  QByteArray bytes;
  QBuffer buffer(&bytes);
  buffer.open(QIODevice::WriteOnly);
  const QPixmap pixmap = w->grab();
  if (pixmap.isNull() || !pixmap.save(&buffer, "PNG")) {
    if (error) *error = QStringLiteral("%1: cannot render %2").arg(path, title);
    return false;
  }
  buffer.close();
  return commit(bytes, path, error);
}

bool save_painted_image(const QString& path, const QSize& size, const QString& title,
                        const std::function<void(QPainter&)>& paint, QString* error) {
  const auto fail = [&](const QString& why) {
    if (error) *error = QStringLiteral("%1: %2").arg(path, why);
    return false;
  };
  if (!is_image_path(path)) return fail(QStringLiteral("unknown image type (use .png or .svg)"));
  if (size.width() < 16 || size.height() < 16 || size.width() > 10000 || size.height() > 10000)
    return fail(QStringLiteral("an image of %1 x %2 pixels: expected 16 to 10000 each way").arg(size.width()).arg(size.height()));
  QByteArray bytes;
  QBuffer buffer(&bytes);
  buffer.open(QIODevice::WriteOnly);
  if (QFileInfo(path).suffix().toLower() == QLatin1String("png")) {
    QImage image(size, QImage::Format_ARGB32_Premultiplied);
    image.fill(Qt::white);
    QPainter painter;
    if (image.isNull() || !painter.begin(&image)) return fail(QStringLiteral("cannot render %1").arg(title));
    painter.setRenderHint(QPainter::Antialiasing);
    paint(painter);
    painter.end();
    if (!image.save(&buffer, "PNG")) return fail(QStringLiteral("cannot encode %1 as PNG").arg(title));
  } else {
    QSvgGenerator svg;
    svg.setOutputDevice(&buffer);
    svg.setSize(size);
    svg.setResolution(96);  // CSS pixels: a browser shows the drawing at `size`
    svg.setViewBox(QRect(QPoint(0, 0), size));
    svg.setTitle(title);
    QPainter painter;
    if (!painter.begin(&svg)) return fail(QStringLiteral("cannot start the SVG output"));
    painter.setRenderHint(QPainter::Antialiasing);
    painter.fillRect(QRect(QPoint(0, 0), size), Qt::white);
    paint(painter);
    painter.end();
  }
  buffer.close();
  return commit(bytes, path, error);
}

}  // namespace codyna::gui
