#include "gui/view3d.hpp"

#include <QElapsedTimer>
#include <QGuiApplication>
#include <QKeyEvent>
#include <QLabel>
#include <QMouseEvent>
#include <QOffscreenSurface>
#include <QOpenGLBuffer>
#include <QOpenGLContext>
#include <QOpenGLExtraFunctions>
#include <QOpenGLShaderProgram>
#include <QOpenGLVertexArrayObject>
#include <QOpenGLWidget>
#include <QPainter>
#include <QVBoxLayout>
#include <QWheelEvent>
#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>

#include "study/tools.hpp"

namespace codyna::gui {

namespace {

QSurfaceFormat requestedFormat() {
  QSurfaceFormat f;
  f.setRenderableType(QSurfaceFormat::OpenGL);
  f.setVersion(3, 3);
  f.setProfile(QSurfaceFormat::CoreProfile);
  f.setDepthBufferSize(24);
  f.setStencilBufferSize(8);  // the selected body's outline
  // 4x multisampling; CODYNA_VIEW_SAMPLES=0 halves the frame time on software GL
  bool set = false;
  const int samples = qEnvironmentVariableIntValue("CODYNA_VIEW_SAMPLES", &set);
  f.setSamples(set ? std::clamp(samples, 0, 16) : 4);
  return f;
}

struct Probe {
  bool ok = false;
  QString reason;
};

Probe probeOpenGL() {
  Probe r;
  const QString platform = QGuiApplication::platformName();
  if (platform == QLatin1String("offscreen") || platform == QLatin1String("minimal")) {
    // these platforms have no usable GL here, and a QOpenGLWidget on them crashes when grabbed
    r.reason = QStringLiteral("no OpenGL context on this display (platform %1)").arg(platform);
    return r;
  }
  QOpenGLContext ctx;
  ctx.setFormat(requestedFormat());
  if (!ctx.create()) {
    r.reason = QStringLiteral("no OpenGL context on this display (platform %1)").arg(platform);
    return r;
  }
  QOffscreenSurface surface;
  surface.setFormat(ctx.format());
  surface.create();
  if (!surface.isValid() || !ctx.makeCurrent(&surface)) {
    r.reason = QStringLiteral("an OpenGL context cannot be made current (platform %1)").arg(platform);
    return r;
  }
  const auto v = ctx.format().version();
  if (v < qMakePair(3, 3)) {
    r.reason = QStringLiteral("OpenGL %1.%2 found, 3.3 needed").arg(v.first).arg(v.second);
  } else {
    r.ok = true;
  }
  ctx.doneCurrent();
  return r;
}

const Probe* cachedProbe() {
  static Probe probe;
  static bool done = false;
  if (!done) {
    if (!qobject_cast<QGuiApplication*>(QCoreApplication::instance())) return nullptr;  // ask again later
    probe = probeOpenGL();
    done = true;
  }
  return &probe;
}

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aColor;
uniform mat4 uMvp;
uniform mat4 uModelView;
uniform mat3 uNormalMat;
out vec3 vNormal;
out vec3 vColor;
out vec3 vPos;
void main() {
  vNormal = uNormalMat * aNormal;
  vColor = aColor;
  vPos = (uModelView * vec4(aPos, 1.0)).xyz;
  gl_Position = uMvp * vec4(aPos, 1.0);
}
)";

// lambert from a key and a fill light fixed to the camera, ambient, a faint highlight
const char* kFragmentShader = R"(#version 330 core
in vec3 vNormal;
in vec3 vColor;
in vec3 vPos;
uniform vec4 uColor;
uniform int uLit;
uniform float uHighlight;
out vec4 fragColor;
void main() {
  vec3 base = mix(uColor.rgb * vColor, vec3(1.0, 0.5, 0.0), uHighlight);
  if (uLit == 0) { fragColor = vec4(base, uColor.a); return; }
  vec3 v = normalize(-vPos);
  vec3 n = normalize(vNormal);
  if (dot(n, v) < 0.0) n = -n;  // two-sided: mirrored frames and cut-open views stay lit
  vec3 key = normalize(vec3(-0.35, 0.75, 0.55));
  vec3 fill = normalize(vec3(0.6, -0.3, 0.75));
  float diffuse = 0.62 * max(dot(n, key), 0.0) + 0.28 * max(dot(n, fill), 0.0);
  float spec = 0.18 * pow(max(dot(n, normalize(key + v)), 0.0), 48.0);
  // a highlighted body is also brighter, so that an orange body still stands out
  fragColor = vec4(base * (0.32 + 0.45 * uHighlight + diffuse) + vec3(spec), uColor.a);
}
)";

Eigen::Matrix4f toGL(const Eigen::Matrix4d& m) { return m.cast<float>(); }

// a note drawn over the 3-D view (the draft's, the tire forces' legend): its own colours, clicks
// pass through it to the view
QLabel* overlay_label(QWidget* parent, const QString& name, const QColor& window, const QColor& text) {
  auto* label = new QLabel(parent);
  label->setObjectName(name);
  label->setAutoFillBackground(true);
  label->setMargin(4);
  label->setAttribute(Qt::WA_TransparentForMouseEvents);
  QPalette pal = label->palette();
  pal.setColor(QPalette::Window, window);
  pal.setColor(QPalette::WindowText, text);
  label->setPalette(pal);
  return label;
}

}  // namespace

// ---- the OpenGL canvas (only made when openGLAvailable()) ----

class GLCanvas : public QOpenGLWidget, protected QOpenGLExtraFunctions {
 public:
  explicit GLCanvas(View3D* owner) : QOpenGLWidget(owner), owner_(owner) {
    setFormat(requestedFormat());
    setMinimumSize(64, 64);
  }
  ~GLCanvas() override {
    disconnect(context_gone_);
    cleanup();
  }
  void gridChanged() { grid_dirty_ = paths_dirty_ = true; }

 protected:
  void initializeGL() override {
    // moving the widget to another window gives it a new context: start over then
    disconnect(context_gone_);
    context_gone_ = connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, [this] { cleanup(); });
    initializeOpenGLFunctions();
    program_ = std::make_unique<QOpenGLShaderProgram>();
    program_->addShaderFromSourceCode(QOpenGLShader::Vertex, kVertexShader);
    program_->addShaderFromSourceCode(QOpenGLShader::Fragment, kFragmentShader);
    if (!program_->link()) {
      qWarning("View3D: shader link failed: %s", qPrintable(program_->log()));
      return;
    }
    u_mvp_ = program_->uniformLocation("uMvp");
    u_mv_ = program_->uniformLocation("uModelView");
    u_nrm_ = program_->uniformLocation("uNormalMat");
    u_color_ = program_->uniformLocation("uColor");
    u_lit_ = program_->uniformLocation("uLit");
    u_hl_ = program_->uniformLocation("uHighlight");

    // 24 segments keep software rendering quick and cylinders round enough
    upload(prims_[int(Prim::Box)], unitBox().data, true);
    upload(prims_[int(Prim::Cylinder)], unitCylinder(28).data, true);
    upload(prims_[int(Prim::Sphere)], unitSphere(28, 14).data, true);
    upload(prims_[int(Prim::Cone)], unitCone(24).data, true);
    upload(prims_[int(Prim::Arrow)], arrowMesh(10).data, true);
    upload(prims_[int(Prim::Triad)], triadMesh(8).data, true);  // small and many: few segments

    // vertical gradient, light at the bottom so the grid reads as a floor
    const float top[3] = {0.74f, 0.79f, 0.86f}, bottom[3] = {0.95f, 0.955f, 0.965f};
    std::vector<float> bg;
    auto corner = [&](float x, float y) {
      const float* c = y > 0 ? top : bottom;
      bg.insert(bg.end(), {x, y, 0.0f, c[0], c[1], c[2]});
    };
    for (auto [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}})
      corner(x, y);
    upload(background_, bg, false);
    grid_dirty_ = true;
    ready_ = true;
  }

  void paintGL() override {
    QElapsedTimer timer;
    timer.start();
    const qreal dpr = devicePixelRatioF();
    glViewport(0, 0, int(width() * dpr), int(height() * dpr));
    glClearColor(0.9f, 0.9f, 0.92f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    if (!ready_) return;

    owner_->syncViewport();
    const Camera& cam = owner_->camera_;
    const Scene& scene = owner_->scene_;
    const Eigen::Matrix4f V = toGL(cam.viewMatrix()), P = toGL(cam.projectionMatrix()), PV = P * V;

    program_->bind();
    const Eigen::Matrix4f I4 = Eigen::Matrix4f::Identity();
    const Eigen::Matrix3f I3 = Eigen::Matrix3f::Identity();

    glDisable(GL_DEPTH_TEST);
    setTransform(I4, I4, I3);
    setLook(Eigen::Vector4f::Ones(), false, 0.0f);
    draw(background_, GL_TRIANGLES);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);

    if (owner_->show_grid_) {
      if (grid_dirty_) {
        upload(grid_, scene.gridLines(), false);
        grid_dirty_ = false;
      }
      setTransform(PV, V, I3);
      draw(grid_, GL_LINES);
    }
    if (!scene.paths().empty() || paths_.count > 0) {
      if (paths_dirty_) {
        upload(paths_, scene.pathMesh().data, true);
        paths_dirty_ = false;
      }
      setTransform(PV, V, V.topLeftCorner<3, 3>());
      setLook(Eigen::Vector4f::Ones(), true, 0.0f);
      draw(paths_, GL_TRIANGLES);
    }

    const int hl = owner_->highlight_body_;
    const auto selected = [hl](const Item& it) { return it.kind == ItemKind::Shape && it.body == hl && hl > 0; };
    // layers: 0 the bodies and elements; 1 the overlays: frames and joint axes, centres of mass,
    // and the elements' marks (couplers, motion inputs, mixed actuators), which sit in bodies too
    // and are shown and hidden with the frames (View > Show frames); 2 the tire forces, which start
    // at the contact inside the tire. Layers 1 and 2 are drawn over the bodies, faint where hidden.
    const auto layerOf = [](const Item& it) {
      if (it.kind == ItemKind::TireLoad || it.kind == ItemKind::TireInPlane) return 2;
      const bool overlay = it.kind == ItemKind::Axis || it.kind == ItemKind::Frame || it.kind == ItemKind::Com ||
                           it.kind == ItemKind::Coupler || it.kind == ItemKind::Motion || it.kind == ItemKind::Actuator;
      return overlay ? 1 : 0;
    };
    auto drawItems = [&](int layer, float alpha) {
      const bool overlays = layer > 0;
      for (const Item& it : scene.items()) {
        if (layerOf(it) != layer) continue;
        if (it.kind == ItemKind::Com ? !owner_->show_com_ : layer == 1 && !owner_->show_frames_) continue;
        const Eigen::Matrix4f MV = V * it.world.matrix().cast<float>();
        const Eigen::Matrix3f A = MV.topLeftCorner<3, 3>();
        if (std::abs(A.determinant()) < 1e-30f) continue;  // degenerate (zero-length spring)
        setTransform(P * MV, MV, A.inverse().transpose());
        Eigen::Vector4f color = it.color;
        color[3] *= alpha;
        // the selected body's shapes mark their whole silhouette in the stencil (hidden parts too)
        if (!overlays && selected(it)) {
          glEnable(GL_STENCIL_TEST);
          glStencilFunc(GL_ALWAYS, 1, 0xFF);
          glStencilOp(GL_KEEP, GL_REPLACE, GL_REPLACE);
          glStencilMask(0xFF);
        }
        setLook(color, true, selected(it) ? 0.35f : 0.0f);
        draw(prims_[int(it.prim)], GL_TRIANGLES);
        if (!overlays && selected(it)) glDisable(GL_STENCIL_TEST);
      }
    };
    drawItems(0, 1.0f);
    if (hl > 0) {
      // the outline: the selected shapes grown by ~2.5 px, drawn where the stencil is not set,
      // over everything (a body behind another still shows where it is)
      glEnable(GL_STENCIL_TEST);
      glStencilFunc(GL_NOTEQUAL, 1, 0xFF);
      glStencilMask(0x00);
      glDisable(GL_DEPTH_TEST);
      const double px = 2.0 * std::tan(0.5 * cam.fovy) / std::max(1, cam.height);  // world per pixel at unit depth
      for (const Item& it : scene.items()) {
        if (!selected(it)) continue;
        const double depth = std::max(cam.nearPlane(), (it.world.translation() - cam.eye()).dot(cam.forward()));
        const double grow = 2.5 * px * depth;
        // unit primitives: a box spans 1 along each axis, a sphere 2, a cylinder 2 across and 1 along
        const bool round = it.prim == Prim::Sphere, tube = it.prim == Prim::Cylinder || it.prim == Prim::Cone;
        Eigen::Vector3d f;
        for (int a = 0; a < 3; ++a) {
          const double n = it.world.linear().col(a).norm();
          const double span = n * ((round || (tube && a < 2)) ? 2.0 : 1.0);
          f[a] = span > 1e-12 ? (span + 2.0 * grow) / span : 1.0;
        }
        const Eigen::Matrix4f MV = V * (it.world * Eigen::Scaling(f)).matrix().cast<float>();
        const Eigen::Matrix3f A = MV.topLeftCorner<3, 3>();
        if (std::abs(A.determinant()) < 1e-30f) continue;
        setTransform(P * MV, MV, A.inverse().transpose());
        setLook(Eigen::Vector4f(1.0f, 0.5f, 0.0f, 1.0f), false, 0.0f);
        draw(prims_[int(it.prim)], GL_TRIANGLES);
      }
      glEnable(GL_DEPTH_TEST);
      glStencilMask(0xFF);
      glDisable(GL_STENCIL_TEST);
    }
    for (int layer : {1, 2}) {
      if (layer == 1 && !owner_->show_frames_ && !owner_->show_com_) continue;
      // frames, axes and the tire forces often sit inside bodies: show their hidden parts faintly first
      glDepthFunc(GL_GREATER);
      glDepthMask(GL_FALSE);
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      drawItems(layer, 0.4f);
      glDisable(GL_BLEND);
      glDepthMask(GL_TRUE);
      glDepthFunc(GL_LEQUAL);
      drawItems(layer, 1.0f);
    }
    program_->release();

    glFinish();
    owner_->last_frame_ms_ = timer.nsecsElapsed() * 1e-6;
    ++owner_->frames_;
  }

 private:
  struct GpuMesh {
    QOpenGLVertexArrayObject vao;
    QOpenGLBuffer vbo;
    int count = 0;
  };

  // with normals: x y z nx ny nz r g b; without: x y z r g b (lines, background)
  void upload(GpuMesh& g, const std::vector<float>& data, bool with_normals) {
    const int stride = with_normals ? 9 : 6;
    if (!g.vao.isCreated()) g.vao.create();
    g.vao.bind();
    if (!g.vbo.isCreated()) g.vbo.create();
    g.vbo.bind();
    g.vbo.allocate(data.data(), int(data.size() * sizeof(float)));
    const GLsizei bytes = GLsizei(stride * sizeof(float));
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, bytes, nullptr);
    if (with_normals) {
      glEnableVertexAttribArray(1);
      glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, bytes, reinterpret_cast<void*>(3 * sizeof(float)));
    } else {
      glDisableVertexAttribArray(1);
    }
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, bytes,
                          reinterpret_cast<void*>((with_normals ? 6 : 3) * sizeof(float)));
    g.vao.release();
    g.vbo.release();
    g.count = int(data.size()) / stride;
  }

  void destroy(GpuMesh& g) {
    g.vbo.destroy();
    g.vao.destroy();
    g.count = 0;
  }

  void cleanup() {
    if (!program_) return;
    makeCurrent();
    for (auto& g : prims_) destroy(g);
    destroy(grid_);
    destroy(paths_);
    destroy(background_);
    program_.reset();
    ready_ = false;
    doneCurrent();
  }

  void setTransform(const Eigen::Matrix4f& mvp, const Eigen::Matrix4f& mv, const Eigen::Matrix3f& normal) {
    glUniformMatrix4fv(u_mvp_, 1, GL_FALSE, mvp.data());
    glUniformMatrix4fv(u_mv_, 1, GL_FALSE, mv.data());
    glUniformMatrix3fv(u_nrm_, 1, GL_FALSE, normal.data());
  }

  void setLook(const Eigen::Vector4f& color, bool lit, float highlight) {
    glUniform4f(u_color_, color[0], color[1], color[2], color[3]);
    glUniform1i(u_lit_, lit ? 1 : 0);
    glUniform1f(u_hl_, highlight);
  }

  void draw(GpuMesh& g, GLenum mode) {
    if (g.count == 0) return;
    g.vao.bind();
    glDrawArrays(mode, 0, g.count);
    g.vao.release();
  }

  View3D* owner_;
  std::unique_ptr<QOpenGLShaderProgram> program_;
  QMetaObject::Connection context_gone_;
  std::array<GpuMesh, 6> prims_;
  GpuMesh grid_, background_, paths_;
  bool grid_dirty_ = true, paths_dirty_ = true, ready_ = false;
  int u_mvp_ = -1, u_mv_ = -1, u_nrm_ = -1, u_color_ = -1, u_lit_ = -1, u_hl_ = -1;
};

// ---- View3D ----

View3D::View3D(QWidget* parent) : QWidget(parent) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  setFocusPolicy(Qt::StrongFocus);
  setMinimumSize(120, 90);
  if (openGLAvailable()) {
    canvas_ = new GLCanvas(this);
    layout->addWidget(canvas_);
  } else {
    placeholder_ = new QLabel(QStringLiteral("3-D view unavailable: %1").arg(openGLUnavailableReason()), this);
    placeholder_->setObjectName(QStringLiteral("view3dPlaceholder"));
    placeholder_->setAlignment(Qt::AlignCenter);
    placeholder_->setWordWrap(true);
    placeholder_->setAutoFillBackground(true);
    QPalette pal = placeholder_->palette();
    pal.setColor(QPalette::Window, QColor(222, 227, 234));
    pal.setColor(QPalette::WindowText, QColor(70, 75, 85));
    placeholder_->setPalette(pal);
    layout->addWidget(placeholder_);
  }
  scene_.build(nullptr);
  camera_.setUp(scene_.up());
  camera_.yaw = Camera::kDefaultYaw, camera_.pitch = Camera::kDefaultPitch;
  syncViewport();
  updateSceneRadius();
  camera_.fit(scene_.bounds());
}

View3D::~View3D() = default;

bool View3D::openGLAvailable() {
  const Probe* p = cachedProbe();
  return p && p->ok;
}

QString View3D::openGLUnavailableReason() {
  const Probe* p = cachedProbe();
  if (!p) return QStringLiteral("no QGuiApplication");
  return p->ok ? QString() : p->reason;
}

bool View3D::hasGL() const { return canvas_ != nullptr; }

void View3D::setDraft(std::shared_ptr<const codyna::Model> draft, const QString& note, const QStringList& held) {
  setModel(std::move(draft));
  if (model_ && !held.isEmpty()) {
    std::vector<int> bodies;
    for (const QString& b : held) bodies.push_back(model_->find_body(b.toStdString()));
    scene_.build(model_.get(), bodies);
    scene_.update(poses_->at(q_));
    updateTireForces();
    updateSceneRadius();
    if (canvas_) canvas_->gridChanged();
  }
  if (!draft_note_) {
    draft_note_ = overlay_label(this, QStringLiteral("view3dDraftNote"), QColor(255, 244, 214), QColor(90, 60, 0));
    draft_note_->setWordWrap(true);
  }
  draft_note_->setText(note);
  draft_note_->setMaximumWidth(std::max(160, width() - 16));
  draft_note_->adjustSize();
  draft_note_->move(8, 8);
  draft_note_->setVisible(!note.isEmpty());
  draft_note_->raise();
  if (auto_fit_) fitView();  // a model being built grows: keep it in sight until the user takes the camera
}

QString View3D::draftNote() const { return draft_note_ && !draft_note_->isHidden() ? draft_note_->text() : QString(); }

void View3D::setPaths(std::vector<ScenePath> paths) {
  scene_.setPaths(std::move(paths));
  updateSceneRadius();
  if (canvas_) canvas_->gridChanged();
  requestPaint();
}

void View3D::setFollowBody(int body) {
  follow_body_ = model_ && body > 0 && body < model_->nbodies ? body : -1;
  follow_at_ = Eigen::Vector3d::Constant(std::nan(""));
  if (follow_body_ > 0 && q_.size() == model_->nq) follow_at_ = poses_->at(q_)[static_cast<std::size_t>(follow_body_)].p;
}

void View3D::frameBody(int body, double radius) {
  if (!model_ || body <= 0 || body >= model_->nbodies || q_.size() != model_->nq || !(radius > 0)) return;
  const Eigen::Vector3d at = poses_->at(q_)[static_cast<std::size_t>(body)].p, u = scene_.up();
  const Eigen::Vector3d ground = at - (at.dot(u) - scene_.gridCenter().dot(u)) * u;
  const Eigen::Vector3d e1 = camera_.front, e2 = u.cross(e1);
  Eigen::AlignedBox3d box;
  for (int i : {-1, 1})
    for (int j : {-1, 1}) box.extend(ground + radius * (i * e1 + j * e2));
  // as tall as the mechanism
  const Eigen::AlignedBox3d b = scene_.bounds();
  double top = 0;
  for (int k = 0; k < 8; ++k) top = std::max(top, (b.corner(static_cast<Eigen::AlignedBox3d::CornerType>(k)) - ground).dot(u));
  box.extend(ground + top * u);
  syncViewport();
  camera_.fit(box);
  auto_fit_ = false;
  updateSceneRadius();
  requestPaint();
}

void View3D::setModel(std::shared_ptr<const codyna::Model> model) {
  if (draft_note_) draft_note_->hide();
  follow_body_ = -1;
  poses_.reset();
  model_ = std::move(model);
  poses_ = model_ ? std::make_unique<codyna::StudyPoses>(*model_) : nullptr;
  q_ = model_ ? model_->q0 : Eigen::VectorXd();
  s_.resize(0);
  v_ = model_ ? model_->v0 : Eigen::VectorXd();
  scene_.build(model_.get());
  if (model_ && q_.size() == model_->nq) {
    scene_.update(poses_->at(q_));
  }
  updateTireForces();
  highlight_body_ = model_ ? model_->find_body(highlight_.toStdString()) : -1;
  camera_.setUp(scene_.up());
  updateSceneRadius();
  // a new model (not an edit of the current one) gets a fresh view
  const std::string key = model_ ? model_->source_file + "\n" + model_->name : std::string();
  if (model_ && key != fitted_for_) {
    fitted_for_ = key;
    resetView();
  }
  if (canvas_) canvas_->gridChanged();
  requestPaint();
}

void View3D::setConfiguration(const Eigen::VectorXd& q) {
  s_.resize(0);  // a pose alone: the deflections at rest there
  applyConfiguration(q);
}

void View3D::applyConfiguration(const Eigen::VectorXd& q) {
  if (!model_ || q.size() != model_->nq) return;
  q_ = q;
  if (v_.size() != model_->nv) v_ = Eigen::VectorXd::Zero(model_->nv);
  const std::vector<SE3>& oMi = poses_->at(q_);
  scene_.update(oMi);
  if (follow_body_ > 0 && follow_body_ < static_cast<int>(oMi.size())) {
    const Eigen::Vector3d at = oMi[static_cast<std::size_t>(follow_body_)].p;
    if (follow_at_.allFinite()) {
      camera_.target += at - follow_at_;
      updateSceneRadius();
    }
    follow_at_ = at;
  }
  updateTireForces();
  requestPaint();
}

void View3D::setState(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& s) {
  if (!model_ || q.size() != model_->nq || v.size() != model_->nv) return;
  v_ = v;
  s_ = s.size() == model_->ns ? s : Eigen::VectorXd();
  applyConfiguration(q);
}

void View3D::setShowTireForces(bool on) {
  show_tire_forces_ = on;
  updateTireForces();
  requestPaint();
}

QString View3D::tireForceLegend() const {
  if (!tire_legend_ || tire_legend_->isHidden()) return {};
  return tire_legend_->property("plainText").toString();
}

void View3D::updateTireForces() {
  contacts_.clear();
  if (model_ && show_tire_forces_ && !model_->tires.empty() && q_.size() == model_->nq && v_.size() == model_->nv) {
    try {
      contacts_ = codyna::study_tire_contacts(*model_, q_, v_, s_.size() == model_->ns ? s_ : Eigen::VectorXd());
    } catch (const std::exception&) {
      contacts_.clear();  // a state the model cannot hold: nothing to draw
    }
  }
  scene_.setTireForces(contacts_);
  const std::string scale = scene_.tireForceScaleText();
  const bool shown = !scale.empty() && std::any_of(contacts_.begin(), contacts_.end(),
                                                   [](const codyna::TireContactReport& c) { return c.in_contact; });
  if (!shown) {
    if (tire_legend_) tire_legend_->hide();
    return;
  }
  if (!tire_legend_) {
    tire_legend_ = overlay_label(this, QStringLiteral("view3dTireLegend"), QColor(250, 250, 252), QColor(40, 44, 52));
    tire_legend_->setTextFormat(Qt::RichText);
  }
  const QString s = QString::fromStdString(scale);
  tire_legend_->setProperty("plainText",
                            tr("tire forces at the contact points, %1: blue the load Fz, teal the in-plane force Fx ex + Fy ey")
                                .arg(s));
  tire_legend_->setText(tr("tire forces at the contact points, <b>%1</b><br><span style=\"color:#1f61f2\">&#9632;</span> load "
                           "F<sub>z</sub> &nbsp; <span style=\"color:#009e8f\">&#9632;</span> in-plane F<sub>x</sub> e<sub>x</sub> "
                           "+ F<sub>y</sub> e<sub>y</sub>")
                            .arg(s));
  tire_legend_->adjustSize();
  tire_legend_->move(8, std::max(8, height() - tire_legend_->height() - 8));
  tire_legend_->show();
  tire_legend_->raise();
}

void View3D::setHighlight(const QString& bodyName) {
  highlight_ = bodyName;
  highlight_body_ = model_ && !bodyName.isEmpty() ? model_->find_body(bodyName.toStdString()) : -1;
  requestPaint();
}

void View3D::setShowFrames(bool on) {
  show_frames_ = on;
  requestPaint();
}

void View3D::setShowCom(bool on) {
  show_com_ = on;
  requestPaint();
}

void View3D::setShowGrid(bool on) {
  show_grid_ = on;
  requestPaint();
}

void View3D::fitView() {
  syncViewport();
  camera_.fit(scene_.viewBounds(show_frames_));
  updateSceneRadius();
  auto_fit_ = true;
  requestPaint();
}

void View3D::resetView() {
  camera_.yaw = Camera::kDefaultYaw;
  camera_.pitch = Camera::kDefaultPitch;
  fitView();
}

QString View3D::pickBody(QPoint pos) const {
  Camera cam = camera_;
  cam.width = width(), cam.height = height();
  const int body = scene_.pick(cam.rayAt(pos.x() + 0.5, pos.y() + 0.5));
  if (!model_ || body <= 0) return {};
  return QString::fromStdString(model_->body_names[body]);
}

bool View3D::bodyScreenPos(const QString& bodyName, QPointF* pos) const {
  if (!model_) return false;
  const int body = model_->find_body(bodyName.toStdString());
  Eigen::Vector3d p;
  if (body <= 0 || !scene_.bodyAnchor(body, &p)) return false;
  Camera cam = camera_;
  cam.width = width(), cam.height = height();
  Eigen::Vector2d px;
  if (!cam.project(p, &px)) return false;
  *pos = QPointF(px.x(), px.y());
  return true;
}

QImage View3D::grabImage() {
  if (canvas_) {
    QImage img = canvas_->grabFramebuffer();
    if (!img.isNull()) {
      if (tire_legend_ && !tire_legend_->isHidden()) {
        // the legend is a widget over the canvas, not in its framebuffer: put it where it is seen
        // (a painter on an image works in its logical pixels, the widgets')
        QPainter painter(&img);
        tire_legend_->render(&painter, tire_legend_->pos());
      }
      return img;
    }
  }
  return grab().toImage();
}

void View3D::resizeEvent(QResizeEvent* e) {
  QWidget::resizeEvent(e);
  if (tire_legend_) tire_legend_->move(8, std::max(8, height() - tire_legend_->height() - 8));
  syncViewport();
  if (auto_fit_) fitView();  // the first layout pass gives the real aspect ratio
}

void View3D::syncViewport() {
  camera_.width = std::max(width(), 1);
  camera_.height = std::max(height(), 1);
}

void View3D::updateSceneRadius() {
  Eigen::AlignedBox3d box = scene_.bounds();
  const Eigen::Vector3d c = scene_.gridCenter(), u = scene_.up();
  const Eigen::Vector3d e1 = camera_.front, e2 = u.cross(e1);
  const double h = scene_.gridHalf();
  for (int i : {-1, 1})
    for (int j : {-1, 1}) box.extend(c + h * (i * e1 + j * e2));
  camera_.scene_radius = std::max(0.5 * box.diagonal().norm(), 1e-9) + (box.center() - camera_.target).norm();
}

void View3D::requestPaint() {
  if (canvas_) canvas_->update();
}

// ---- input ----

void View3D::mousePressEvent(QMouseEvent* e) {
  press_pos_ = last_pos_ = e->position().toPoint();
  pressed_ = true;
  dragged_ = false;
  e->accept();
}

void View3D::mouseMoveEvent(QMouseEvent* e) {
  if (!pressed_) return;
  const QPoint p = e->position().toPoint();
  if ((p - press_pos_).manhattanLength() > 3) dragged_ = true;
  if (!dragged_) return;
  const QPoint d = p - last_pos_;
  last_pos_ = p;
  const bool pan = (e->buttons() & Qt::MiddleButton) ||
                   ((e->buttons() & Qt::LeftButton) && (e->modifiers() & Qt::ShiftModifier));
  if (pan) {
    camera_.pan(d.x(), d.y());
  } else if (e->buttons() & Qt::LeftButton) {
    camera_.orbit(d.x(), d.y());
  } else if (e->buttons() & Qt::RightButton) {
    camera_.zoom(-d.y() / 40.0);
  } else {
    return;
  }
  auto_fit_ = false;
  updateSceneRadius();
  requestPaint();
}

void View3D::mouseReleaseEvent(QMouseEvent* e) {
  if (pressed_ && !dragged_ && e->button() == Qt::LeftButton) emit bodyPicked(pickBody(e->position().toPoint()));
  pressed_ = false;
}

void View3D::mouseDoubleClickEvent(QMouseEvent* e) {
  if (e->button() == Qt::LeftButton && pickBody(e->position().toPoint()).isEmpty()) fitView();
}

void View3D::wheelEvent(QWheelEvent* e) {
  camera_.zoom(e->angleDelta().y() / 120.0);
  auto_fit_ = false;
  updateSceneRadius();
  requestPaint();
  e->accept();
}

void View3D::keyPressEvent(QKeyEvent* e) {
  if (e->key() == Qt::Key_F) {
    fitView();
    return;
  }
  QWidget::keyPressEvent(e);
}

}  // namespace codyna::gui
