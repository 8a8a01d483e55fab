// View3D: the 3-D view of a mechanism.
//
// Draws the bodies of a Model at a configuration q (declared shapes, or a
// default ball-and-link look for bodies without shapes), joint axes, body
// frames, centres of mass (on request), ground anchors, springs, the selected
// body tinted and outlined (its silhouette, also where other bodies hide it),
// the tires' contact forces at the state (q, v) shown (arrows from the contact
// points, core's study_tire_contacts, with a legend giving their scale),
// and a ground grid normal to "up"
// (-gravity, else +y), with an orbit camera:
//   left drag: orbit    middle drag or shift + left drag: pan    wheel: zoom
//   F or double click on the background: fit    left click: pick a body
//
// OpenGL is probed once before any QOpenGLWidget exists; without it (e.g.
// QT_QPA_PLATFORM=offscreen) the view shows a placeholder label instead and
// everything else (camera, picking, projection) still works on the CPU.
#pragma once

#include <QImage>
#include <QPoint>
#include <QPointF>
#include <QString>
#include <QStringList>
#include <QWidget>
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "gui/scene3d.hpp"
#include "study/tire_contacts.hpp"
#include "study/tools.hpp"
#include "model/model.hpp"

class QLabel;

namespace codyna::gui {

class GLCanvas;

class View3D : public QWidget {
  Q_OBJECT

 public:
  explicit View3D(QWidget* parent = nullptr);
  ~View3D() override;

  // true when an OpenGL 3.3 context can be made current on this platform;
  // probed once per process (needs a QGuiApplication), false under offscreen
  static bool openGLAvailable();
  // why not, for the placeholder ("" when available)
  static QString openGLUnavailableReason();
  bool hasGL() const;

  // nullptr: empty scene. The camera is fitted when the first model arrives
  // (or one from another file / with another name); an edited model keeps it.
  void setModel(std::shared_ptr<const codyna::Model> model);
  std::shared_ptr<const codyna::Model> model() const { return model_; }
  // a model that does not compile yet, drawn as its draft (study/model_issues.hpp: what compiles of
  // it, the bodies no joint moves held in a row); `note` is shown over the view's top-left corner
  // until the next setModel. The camera follows the draft as it grows until the user moves it.
  // `held`: the bodies the draft holds (no ground anchor is drawn for them)
  void setDraft(std::shared_ptr<const codyna::Model> draft, const QString& note, const QStringList& held = {});
  QString draftNote() const;  // "" when the model shown is not a draft
  // nq values; draws the mechanism there (setModel starts at m.q0, v0). Cheap:
  // forward kinematics and item transforms only. Wrong sizes are ignored. The
  // tire forces are those at q with the velocities last given (setState).
  void setConfiguration(const Eigen::VectorXd& q);
  // the state (nq and nv values): the mechanism at q and the tires' contact forces at (q, v).
  // Wrong sizes are ignored.
  // s: the effect states (a tire's deflections) of a simulation's sample; empty: at rest at (q, v)
  void setState(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& s = {});
  const Eigen::VectorXd& configuration() const { return q_; }
  const Eigen::VectorXd& velocities() const { return v_; }
  // the tires' contacts drawn now (empty: a model without tires, or the tire forces hidden)
  const std::vector<codyna::TireContactReport>& tireContacts() const { return contacts_; }
  void setShowTireForces(bool on);             // the tire force arrows and their legend, default on
  bool showTireForces() const { return show_tire_forces_; }
  // the legend's text ("" when no tire force is drawn)
  QString tireForceLegend() const;
  void setHighlight(const QString& bodyName);  // "" none
  QString highlight() const { return highlight_; }
  void setShowFrames(bool on);                 // body triads and joint axes, default on
  bool showFrames() const { return show_frames_; }
  void setShowCom(bool on);                    // centres of mass (a dark ball at each), default off
  bool showCom() const { return show_com_; }
  void setShowGrid(bool on);                   // ground grid, default on
  bool showGrid() const { return show_grid_; }

  // paths on the ground (a maneuver's lane and the track the car left; Scene::setPaths): drawn
  // with and without OpenGL's picking alike, cleared by setModel; the grid grows to hold them
  void setPaths(std::vector<ScenePath> paths);
  const std::vector<ScenePath>& paths() const { return scene_.paths(); }
  // the camera follows this body (its origin's moves shift the camera's target; -1: none), as a
  // maneuver's run plays; setModel stops it
  void setFollowBody(int body);
  int followBody() const { return follow_body_; }
  // frames the ground `radius` around a body (its origin as drawn now; the grid's height), e.g. a
  // car and the lane about it; no-op for an unknown body
  void frameBody(int body, double radius);

  void fitView();    // frame the whole mechanism, keep the orbit angles
  void resetView();  // default orbit angles, then fit

  // The body under widget position `pos` (widget pixels), "" for background or
  // ground. Ray cast on the CPU against the drawn shapes; works with or
  // without OpenGL, for the current camera and widget size.
  QString pickBody(QPoint pos) const;
  // where a point of the body's geometry (centre of its largest shape) appears
  // in widget pixels; false when the body is unknown or behind the camera
  bool bodyScreenPos(const QString& bodyName, QPointF* pos) const;

  const Camera& camera() const { return camera_; }
  const Scene& scene() const { return scene_; }

  // what is shown: the GL framebuffer with hasGL() (and the tire forces' legend over it), else
  // the placeholder's grab()
  QImage grabImage();
  double lastFrameMs() const { return last_frame_ms_; }  // CPU time of the last paint, after glFinish
  int framesDrawn() const { return frames_; }

 signals:
  void bodyPicked(const QString& bodyName);  // click without drag: body name, "" on background

 protected:
  void resizeEvent(QResizeEvent* e) override;
  // the canvas and the placeholder ignore input, so it reaches these
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void mouseDoubleClickEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;

 private:
  friend class GLCanvas;
  void syncViewport();
  void updateSceneRadius();
  void requestPaint();
  void applyConfiguration(const Eigen::VectorXd& q);  // q_, the scene's poses, the tire forces
  void updateTireForces();  // contacts_ and the scene's arrows at (q_, v_), the legend

  std::shared_ptr<const codyna::Model> model_;
  std::unique_ptr<codyna::StudyPoses> poses_;  // the body poses at q_
  Eigen::VectorXd q_, v_, s_;
  std::vector<codyna::TireContactReport> contacts_;
  Scene scene_;
  Camera camera_;
  QString highlight_;
  int highlight_body_ = -1;
  bool show_frames_ = true, show_grid_ = true, show_com_ = false, show_tire_forces_ = true;
  std::string fitted_for_;   // source file and name of the model the camera was fitted to
  bool auto_fit_ = true;      // refit on resize until the user moves the camera
  int follow_body_ = -1;
  Eigen::Vector3d follow_at_ = Eigen::Vector3d::Constant(std::nan(""));  // where the followed body was last drawn

  GLCanvas* canvas_ = nullptr;
  QLabel* placeholder_ = nullptr;
  QLabel* draft_note_ = nullptr;
  QLabel* tire_legend_ = nullptr;
  QPoint press_pos_, last_pos_;
  bool pressed_ = false, dragged_ = false;
  double last_frame_ms_ = 0.0;
  int frames_ = 0;
};

}  // namespace codyna::gui
