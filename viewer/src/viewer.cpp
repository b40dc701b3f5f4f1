#include "spinesim/viewer/viewer.hpp"
#include "spinesim/common/constants.hpp"

#include <GL/glcorearb.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace spinesim::viewer {

namespace {

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 vertex_color;
uniform mat4 model, view, projection;
out vec3 eye_normal;
out vec3 face_color;
void main() {
  mat4 mv = view * model;
  eye_normal = mat3(mv) * normal;
  face_color = vertex_color;
  gl_Position = projection * mv * vec4(position, 1.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec3 eye_normal;
in vec3 face_color;
uniform vec3 color;
uniform int per_face;
out vec4 fragment;
void main() {
  // A headlight: the light comes from the eye; both faces lit (open or inward-facing surfaces).
  float d = abs(normalize(eye_normal).z);
  vec3 c = per_face != 0 ? face_color : color;
  fragment = vec4(c * (0.25 + 0.75 * d), 1.0);
}
)";

std::string glfw_error;  // the last GLFW error, for the one-line messages
void on_glfw_error(int, const char* description) { glfw_error = description; }

GLuint compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[1024] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("view: shader does not compile: ") + log);
  }
  return s;
}

GLuint link_program() {
  const GLuint p = glCreateProgram();
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  glAttachShader(p, vs);
  glAttachShader(p, fs);
  glLinkProgram(p);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) throw std::runtime_error("view: shader program does not link");
  return p;
}

/// Triangles on the GPU: three vertices each with the face normal and the face colour.
struct GpuMesh {
  GLuint vao = 0, vbo = 0;
  GLsizei vertices = 0;
  std::uint64_t revision = 0;
  bool per_face = false;
  void release() {
    if (vbo) glDeleteBuffers(1, &vbo);
    if (vao) glDeleteVertexArrays(1, &vao);
    vao = vbo = 0;
    vertices = 0;
  }
};

void upload(GpuMesh& m, const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& F,
            const Eigen::MatrixX3f& colors) {
  std::vector<float> data;
  data.reserve(std::size_t(F.rows()) * 27);
  const bool per_face = colors.rows() == F.rows() && F.rows() > 0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), c1 = V.row(F(f, 1)), c2 = V.row(F(f, 2));
    Eigen::Vector3d n = (c1 - a).cross(c2 - a);
    n = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitY();
    const Eigen::Vector3f c = per_face ? Eigen::Vector3f(colors.row(f)) : Eigen::Vector3f::Ones();
    for (const Eigen::Vector3d& p : {a, c1, c2}) {
      for (const double v : {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()}) data.push_back(float(v));
      for (int k = 0; k < 3; ++k) data.push_back(c(k));
    }
  }
  if (!m.vao) {
    glGenVertexArrays(1, &m.vao);
    glGenBuffers(1, &m.vbo);
  }
  m.vertices = GLsizei(data.size() / 9);
  m.per_face = per_face;
  glBindVertexArray(m.vao);
  glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(),
               GL_DYNAMIC_DRAW);
  const GLsizei stride = 9 * sizeof(float);
  for (GLuint k = 0; k < 3; ++k) {
    glVertexAttribPointer(k, 3, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<void*>(std::uintptr_t(3 * k * sizeof(float))));
    glEnableVertexAttribArray(k);
  }
}

/// A unit sphere (an icosahedron subdivided twice) and a unit arrow along +z (a shaft of radius
/// 1 from z = 0 to 1, a cone of radius 2 and height 1 from z = 1 to 2): scaled per marker.
Eigen::MatrixX3d sphere_vertices(Eigen::MatrixX3i& F) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<Eigen::Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < 2; ++level) {
    std::vector<std::array<int, 3>> next;
    for (const auto& t : f) {
      int m[3];
      for (int k = 0; k < 3; ++k) {
        v.push_back(0.5 * (v[std::size_t(t[std::size_t(k)])] + v[std::size_t(t[(k + 1) % 3])]));
        m[k] = int(v.size()) - 1;
      }
      next.push_back({t[0], m[0], m[2]});
      next.push_back({t[1], m[1], m[0]});
      next.push_back({t[2], m[2], m[1]});
      next.push_back({m[0], m[1], m[2]});
    }
    f = next;
  }
  Eigen::MatrixX3d V(Eigen::Index(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) V.row(Eigen::Index(i)) = v[i].normalized();
  F.resize(Eigen::Index(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i) F.row(Eigen::Index(i)) << f[i][0], f[i][1], f[i][2];
  return V;
}

Eigen::MatrixX3d arrow_vertices(Eigen::MatrixX3i& F) {
  const int n = 16;
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<int, 3>> f;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * kPi * i / n, c = std::cos(a), s = std::sin(a);
    v.push_back({c, s, 0});          // 4 i: shaft bottom
    v.push_back({c, s, 1});          // 4 i + 1: shaft top
    v.push_back({2 * c, 2 * s, 1});  // 4 i + 2: cone base
    v.push_back({0, 0, 2});          // 4 i + 3: tip
  }
  for (int i = 0; i < n; ++i) {  // the shaft's 2 n triangles first (drawn on their own)
    const int j = (i + 1) % n;
    f.push_back({4 * i, 4 * j, 4 * j + 1});
    f.push_back({4 * i, 4 * j + 1, 4 * i + 1});
  }
  for (int i = 0; i < n; ++i) {  // then the head: the cone and its underside ring
    const int j = (i + 1) % n;
    f.push_back({4 * i + 2, 4 * j + 2, 4 * i + 3});
    f.push_back({4 * i + 1, 4 * j + 1, 4 * j + 2});
    f.push_back({4 * i + 1, 4 * j + 2, 4 * i + 2});
  }
  Eigen::MatrixX3d V(Eigen::Index(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) V.row(Eigen::Index(i)) = v[i];
  F.resize(Eigen::Index(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i) F.row(Eigen::Index(i)) << f[i][0], f[i][1], f[i][2];
  return V;
}

/// Orbit camera about a target: yaw about the superior (y) axis, pitch above the horizontal.
struct Camera {
  Eigen::Vector3f target = Eigen::Vector3f::Zero();
  float distance = 1000, yaw = 0, pitch = 0, fov = float(35.0 * kRadPerDeg);

  Eigen::Vector3f eye() const {
    const Eigen::Vector3f dir(std::cos(pitch) * std::cos(yaw), std::sin(pitch),
                              std::cos(pitch) * std::sin(yaw));
    return target - distance * dir;
  }
  Eigen::Matrix4f view() const {
    const Eigen::Vector3f e = eye(), f = (target - e).normalized();
    const Eigen::Vector3f s = f.cross(Eigen::Vector3f::UnitY()).normalized(), u = s.cross(f);
    Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
    m.block<1, 3>(0, 0) = s.transpose();
    m.block<1, 3>(1, 0) = u.transpose();
    m.block<1, 3>(2, 0) = -f.transpose();
    m(0, 3) = -s.dot(e), m(1, 3) = -u.dot(e), m(2, 3) = f.dot(e);
    return m;
  }
  Eigen::Matrix4f projection(float aspect) const {
    const float n = 0.01f * distance, fr = 10.0f * distance, t = 1.0f / std::tan(0.5f * fov);
    Eigen::Matrix4f p = Eigen::Matrix4f::Zero();
    p(0, 0) = t / aspect, p(1, 1) = t;
    p(2, 2) = -(fr + n) / (fr - n), p(2, 3) = -2 * fr * n / (fr - n), p(3, 2) = -1;
    return p;
  }
  /// Looks at the bounding sphere (centre c, radius r) from the default direction.
  void frame(const Eigen::Vector3f& c, float r) {
    target = c;
    distance = 1.15f * r / std::sin(0.5f * fov);
    yaw = 0;    // the eye on the body's right (-x): a sagittal view, anterior to the screen's right
    pitch = 0;  // level: the mouse's probe then moves in a sagittal plane
  }
};

/// Pixel (x right, y down) to a world ray, and back, for a viewport of w × h pixels.
struct Projector {
  Eigen::Matrix4f view, proj;
  int w = 1, h = 1;
  Eigen::Vector2d to_pixel(const Eigen::Vector3d& p) const {
    const Eigen::Vector4f c =
        proj * view * Eigen::Vector4f(float(p.x()), float(p.y()), float(p.z()), 1.0f);
    return {(c.x() / c.w() + 1) * 0.5 * w, (1 - c.y() / c.w()) * 0.5 * h};
  }
  void to_ray(double x, double y, Eigen::Vector3d& origin, Eigen::Vector3d& dir) const {
    const Eigen::Matrix4f inv = (proj * view).inverse();
    const float nx = float(2 * x / w - 1), ny = float(1 - 2 * y / h);
    Eigen::Vector4f a = inv * Eigen::Vector4f(nx, ny, -1, 1),
                    b = inv * Eigen::Vector4f(nx, ny, 1, 1);
    a /= a.w(), b /= b.w();
    origin = a.head<3>().cast<double>();
    dir = (b - a).head<3>().cast<double>().normalized();
  }
};

double scroll_accumulated = 0;
void on_scroll(GLFWwindow*, double, double dy) { scroll_accumulated += dy; }

/// Mouse and keyboard: the camera (orbit, pan, zoom) and the pointer for the controller.
class Input {
 public:
  Pointer pointer;

  void handle(GLFWwindow* w, Camera& cam, bool device_mode, const Projector& pr,
              const ViewOptions& o, double now_s) {
    double x = 0, y = 0;
    unsigned scripted_buttons = 0;
    double scripted_wheel = 0;
    const bool scripted = !o.cursor_script.empty();
    if (scripted) {
      Eigen::Vector3d p;
      script_at(o.cursor_script, now_s, p, scripted_buttons, scripted_wheel);
      const Eigen::Vector2d px = pr.to_pixel(p);
      x = px.x(), y = px.y();
    } else {
      glfwGetCursorPos(w, &x, &y);
    }
    const bool want = ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse && !scripted;
    const auto held = [&](int b) { return glfwGetMouseButton(w, b) == GLFW_PRESS && !want; };
    const bool left = held(GLFW_MOUSE_BUTTON_LEFT), right = held(GLFW_MOUSE_BUTTON_RIGHT),
               middle = held(GLFW_MOUSE_BUTTON_MIDDLE);
    const bool shift = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                       glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
    const float dx = float(x - x_), dy = float(y - y_);
    const bool orbit = device_mode ? right : left, pan = device_mode ? middle : right;
    if (orbit && orbit_) {
      cam.yaw += 0.005f * dx;
      cam.pitch = std::clamp(cam.pitch + 0.005f * dy, -1.5f, 1.5f);
    }
    if (pan && pan_) {
      const Eigen::Matrix4f v = cam.view();
      const float scale = cam.distance * 0.0015f;
      cam.target +=
          scale * (-dx * v.block<1, 3>(0, 0).transpose() + dy * v.block<1, 3>(1, 0).transpose());
    }
    x_ = x, y_ = y, orbit_ = orbit, pan_ = pan;

    double wheel = scroll_accumulated;
    scroll_accumulated = 0;
    if (want) wheel = 0;
    Pointer& p = pointer;
    p.wheel = 0;
    if (device_mode && !shift) {
      p.wheel = wheel + scripted_wheel;
    } else {
      cam.distance *= float(std::pow(0.9, wheel));
    }
    int ww = 0, wh = 0;
    glfwGetWindowSize(w, &ww, &wh);
    // Cursor pixels are window coordinates; the projector works in framebuffer pixels.
    const double sx = scripted ? 1.0 : double(pr.w) / std::max(ww, 1),
                 sy = scripted ? 1.0 : double(pr.h) / std::max(wh, 1);
    p.inside = !want && x >= 0 && y >= 0 && x * sx < pr.w && y * sy < pr.h &&
               (scripted || glfwGetWindowAttrib(w, GLFW_HOVERED));
    pr.to_ray(x * sx, y * sy, p.ray_origin, p.ray_direction);
    p.view_direction = (cam.target - cam.eye()).normalized().cast<double>();
    const bool space = glfwGetKey(w, GLFW_KEY_SPACE) == GLFW_PRESS && !want;
    p.buttons = scripted ? scripted_buttons : ((device_mode && (left || space)) ? 1u : 0u);
    p.camera_moving = device_mode && (right || middle);
  }

 private:
  double x_ = 0, y_ = 0;
  bool orbit_ = false, pan_ = false;
  std::size_t wheel_step_ = 0;  ///< script steps whose wheel has been turned

  void script_at(const std::vector<ViewOptions::CursorStep>& s, double t, Eigen::Vector3d& p,
                 unsigned& buttons, double& wheel) {
    std::size_t i = 0;
    while (i + 1 < s.size() && s[i + 1].t_s <= t) ++i;
    if (t <= s.front().t_s || i + 1 >= s.size()) {
      p = t <= s.front().t_s ? s.front().point_mm : s.back().point_mm;
    } else {
      const double f = (t - s[i].t_s) / (s[i + 1].t_s - s[i].t_s);
      p = s[i].point_mm + f * (s[i + 1].point_mm - s[i].point_mm);
    }
    buttons = t >= s.front().t_s ? s[i].buttons : 0;
    wheel = 0;
    while (wheel_step_ < s.size() && s[wheel_step_].t_s <= t) wheel += s[wheel_step_++].wheel;
  }
};

void write_png(const std::string& path, int width, int height) {
  std::vector<unsigned char> pixels(std::size_t(width) * std::size_t(height) * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  // OpenGL's first row is the bottom one; PNG's the top.
  const int stride = width * 3;
  if (!stbi_write_png(path.c_str(), width, height, 3, pixels.data() + (height - 1) * stride,
                      -stride))
    throw std::runtime_error("view: cannot write the screenshot " + path);
}

/// The window with a 3.3 core context, or one line saying why not.
GLFWwindow* open_window(const ViewOptions& o) {
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit())
    throw std::runtime_error("view: no display (" + glfw_error +
                             "): run it on a desktop, or under xvfb-run for screenshots");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* w = glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
  if (!w) {
    glfwTerminate();
    throw std::runtime_error("view: no OpenGL 3.3 core context on this display (" + glfw_error +
                             ")");
  }
  glfwMakeContextCurrent(w);
  glfwSwapInterval(o.screenshot.empty() ? 1 : 0);
  return w;
}

/// Everything on the GPU and the drawing of one frame.
class Renderer {
 public:
  Renderer() : program_(link_program()) {
    Eigen::MatrixX3i F;
    const Eigen::MatrixX3d V = sphere_vertices(F);
    upload(sphere_, V, F, {});
    const Eigen::MatrixX3d A = arrow_vertices(F);
    upload(arrow_, A, F, {});
  }
  ~Renderer() {
    for (GpuMesh& m : bodies_) m.release();
    sphere_.release();
    arrow_.release();
    glDeleteProgram(program_);
  }
  void draw(const SceneFrame& scene, const Eigen::Matrix4f& view, const Eigen::Matrix4f& proj) {
    glUseProgram(program_);
    glUniformMatrix4fv(glGetUniformLocation(program_, "view"), 1, GL_FALSE, view.data());
    glUniformMatrix4fv(glGetUniformLocation(program_, "projection"), 1, GL_FALSE, proj.data());
    if (bodies_.size() < scene.bodies.size()) bodies_.resize(scene.bodies.size());
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
      const Body& b = scene.bodies[i];
      if (!b.visible || b.F.rows() == 0) continue;
      GpuMesh& m = bodies_[i];
      if (!m.vao || m.revision != b.revision) {
        upload(m, b.V, b.F, b.face_colors);
        m.revision = b.revision;
      }
      Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
      model.topLeftCorner<3, 3>() = b.R.cast<float>();
      model.topRightCorner<3, 1>() = b.t.cast<float>();
      draw_mesh(m, model, b.color);
    }
    for (const Marker& mk : scene.markers) draw_marker(mk);
  }

 private:
  GLuint program_;
  std::vector<GpuMesh> bodies_;
  GpuMesh sphere_, arrow_;

  void draw_mesh(const GpuMesh& m, const Eigen::Matrix4f& model, const Eigen::Vector3f& color) {
    glUniformMatrix4fv(glGetUniformLocation(program_, "model"), 1, GL_FALSE, model.data());
    glUniform3fv(glGetUniformLocation(program_, "color"), 1, color.data());
    glUniform1i(glGetUniformLocation(program_, "per_face"), m.per_face ? 1 : 0);
    glBindVertexArray(m.vao);
    glDrawArrays(GL_TRIANGLES, 0, m.vertices);
  }
  void draw_marker(const Marker& mk) {
    Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
    const float r = float(mk.radius_mm);
    if (mk.kind == Marker::Kind::sphere) {
      model.topLeftCorner<3, 3>() = r * Eigen::Matrix3f::Identity();
      model.topRightCorner<3, 1>() = mk.a.cast<float>();
      draw_mesh(sphere_, model, mk.color);
      return;
    }
    const Eigen::Vector3d d = mk.b - mk.a;
    const double length = d.norm();
    if (!(length > 0)) return;
    // The unit arrow is 2 long (shaft 1, head 1): the head takes min(40 %, 6 r) of the length;
    // a rod is all shaft.
    const double head =
        mk.kind == Marker::Kind::rod ? 0.0 : std::min(0.4 * length, 6.0 * mk.radius_mm);
    const Eigen::Vector3d z = d / length;
    const Eigen::Vector3d x =
        (std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY())
            .cross(z)
            .normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d R;
    R << x, y, z;
    // The shaft scaled to length - head, the head (z 1..2) to `head`: two draws.
    Eigen::Matrix3d S = Eigen::Vector3d(r, r, length - head).asDiagonal();
    model.topLeftCorner<3, 3>() = (R * S).cast<float>();
    model.topRightCorner<3, 1>() = mk.a.cast<float>();
    glUniformMatrix4fv(glGetUniformLocation(program_, "model"), 1, GL_FALSE, model.data());
    glUniform3fv(glGetUniformLocation(program_, "color"), 1, mk.color.data());
    glUniform1i(glGetUniformLocation(program_, "per_face"), 0);
    glBindVertexArray(arrow_.vao);
    glDrawArrays(GL_TRIANGLES, 0, 16 * 2 * 3);  // the shaft alone
    if (mk.kind == Marker::Kind::rod) return;
    // The whole unit arrow scaled to `head`: its cone is the head, its shaft lies in the shaft.
    S = Eigen::Vector3d(r, r, head).asDiagonal();
    model.topLeftCorner<3, 3>() = (R * S).cast<float>();
    model.topRightCorner<3, 1>() = (mk.a + (length - 2 * head) * z).cast<float>();
    draw_mesh(arrow_, model, mk.color);
  }
};

/// A still scene.
class StillController final : public Controller {
 public:
  explicit StillController(const std::vector<Body>& bodies) : bodies_(bodies) {}
  void update(SceneFrame& scene, const Pointer&) override {
    if (scene.bodies.empty()) scene.bodies = bodies_;
  }

 private:
  const std::vector<Body>& bodies_;
};

bool bounds(const SceneFrame& s, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  bool any = false;
  for (const Body& b : s.bodies) {
    if (!b.visible) continue;
    for (Eigen::Index i = 0; i < b.V.rows(); ++i) {
      const Eigen::Vector3d p = b.R * b.V.row(i).transpose() + b.t;
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      any = true;
    }
  }
  return any;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(q * double(v.size())))];
}

}  // namespace

void check(const ViewOptions& o) {
  if (o.width < 64 || o.height < 64 || o.width > 8192 || o.height > 8192)
    throw std::invalid_argument("view: the window must be 64 to 8192 pixels each way");
  if (!o.screenshot.empty() && o.frames < 1)
    throw std::invalid_argument("view: --frames must be at least 1");
  if (!(o.screenshot_after_s >= 0) || o.screenshot_after_s > 3600)
    throw std::invalid_argument("view: the screenshot time must be 0 to 3600 s");
  for (std::size_t i = 0; i < o.cursor_script.size(); ++i) {
    const auto& c = o.cursor_script[i];
    if (!std::isfinite(c.t_s) || !c.point_mm.allFinite() || !std::isfinite(c.wheel) ||
        (i > 0 && !(c.t_s > o.cursor_script[i - 1].t_s)))
      throw std::invalid_argument("view: cursor script step " + std::to_string(i + 1) +
                                  ": times must increase and values be finite");
  }
}

ViewResult view(const std::vector<Body>& bodies, const ViewOptions& o) {
  if (bodies.empty()) throw std::invalid_argument("view: nothing to show (no bodies)");
  StillController still(bodies);
  return view(still, o);
}

namespace {

/// The window, its GL context and Dear ImGui, torn down in reverse on every path out.
struct Window {
  GLFWwindow* w;
  explicit Window(const ViewOptions& o) : w(open_window(o)) {
    glfwSetScrollCallback(w, on_scroll);
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left behind
    ImGui_ImplGlfw_InitForOpenGL(w, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
  }
  ~Window() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(w);
    glfwTerminate();
  }
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;
};

/// The panel: what is shown, the frame time, the camera button, the controls, the controller's
/// own contents. True when "reset camera" was pressed.
bool draw_panel(Controller& controller, const SceneFrame& scene, double last_frame_ms,
                const std::string& renderer, int framebuffer_width) {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  // Top left, a third of the window wide at most: the scene is framed in the middle.
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_Once);
  ImGui::SetNextWindowSize(ImVec2(std::clamp(framebuffer_width / 3.0f, 300.0f, 460.0f), 0),
                           ImGuiCond_Always);  // 0: the height fits the contents
  ImGui::Begin("spinesim", nullptr, ImGuiWindowFlags_NoResize);
  ImGui::PushTextWrapPos(0);
  long triangles = 0;
  for (const Body& b : scene.bodies) triangles += b.visible ? long(b.F.rows()) : 0;
  ImGui::Text("%d bodies, %ld triangles", int(scene.bodies.size()), triangles);
  ImGui::Text("frame %.1f ms to draw (%s)", last_frame_ms, renderer.c_str());
  const bool reset = ImGui::Button("reset camera");
  ImGui::TextDisabled(controller.takes_pointer()
                          ? "cursor: probe, left/space: button, wheel: depth; right drag: "
                            "orbit, middle: pan, shift+wheel: zoom"
                          : "left drag: orbit, right drag: pan, wheel: zoom");
  ImGui::Separator();
  controller.panel();
  ImGui::PopTextWrapPos();
  ImGui::End();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  return reset;
}

}  // namespace

ViewResult view(Controller& controller, const ViewOptions& o) {
  check(o);
  struct Closing {  // the controller hears of the end on every path out
    Controller& c;
    ~Closing() { c.closing(); }
  } closing{controller};
  const Window window(o);
  GLFWwindow* w = window.w;
  ViewResult r;
  r.renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  r.gl_version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  std::vector<double> frame_ms;
  Renderer renderer;
  SceneFrame scene;
  Camera cam;
  bool framed = false;
  Input input;
  glEnable(GL_DEPTH_TEST);
  const auto start = std::chrono::steady_clock::now();
  auto last = start, first_shown = start;
  int shown = 0;
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  while (!glfwWindowShouldClose(w) && !controller.done()) {
    const auto frame_start = std::chrono::steady_clock::now();
    glfwPollEvents();
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(w, &fw, &fh);
    const float aspect = float(fw) / float(std::max(fh, 1));
    const Projector pr{cam.view(), cam.projection(aspect), std::max(fw, 1), std::max(fh, 1)};
    const double clock = controller.clock_s(seconds());
    input.handle(w, cam, controller.takes_pointer(), pr, o, std::max(clock, 0.0));
    controller.update(scene, input.pointer);
    const auto reset = [&] {
      Eigen::Vector3d lo, hi;
      if (!bounds(scene, lo, hi)) return;
      cam.frame((0.5 * (lo + hi)).cast<float>(), float(0.5 * (hi - lo).norm()));
      cam.yaw = std::isfinite(o.camera_yaw_deg) ? float(o.camera_yaw_deg * kRadPerDeg)
                                                : controller.initial_yaw();
      if (std::isfinite(o.camera_pitch_deg))  // the eye above the target: a negative pitch
        cam.pitch = std::clamp(float(-o.camera_pitch_deg * kRadPerDeg), -1.5f, 1.5f);
      framed = true;
    };
    if (!framed) reset();
    glViewport(0, 0, fw, fh);
    glClearColor(0.12f, 0.13f, 0.15f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    renderer.draw(scene, cam.view(), cam.projection(aspect));
    if (o.panel &&
        draw_panel(controller, scene, frame_ms.empty() ? 0.0 : frame_ms.back(), r.renderer, fw))
      reset();
    ++r.frames;
    const auto worked = std::chrono::steady_clock::now();
    if (!scene.bodies.empty()) {  // the frames of a scene, not of the wait for one
      frame_ms.push_back(std::chrono::duration<double, std::milli>(worked - frame_start).count());
      if (shown++ == 0) first_shown = frame_start;
    }
    // At most 60 frames a second even without vsync (Xvfb, some drivers): the CPU the
    // graphics do not need stays with the servo and disc threads.
    const auto due = last + std::chrono::microseconds(16667);
    if (worked < due) std::this_thread::sleep_until(due);
    last = std::chrono::steady_clock::now();
    if (!o.screenshot.empty() && r.frames >= o.frames && clock >= o.screenshot_after_s) {
      write_png(o.screenshot, fw, fh);
      break;
    }
    glfwSwapBuffers(w);
  }
  double total = 0;
  for (double ms : frame_ms) total += ms;
  r.mean_frame_ms = frame_ms.empty() ? 0 : total / double(frame_ms.size());
  const double span = std::chrono::duration<double>(last - first_shown).count();
  r.rate_hz = shown > 1 && span > 0 ? (shown - 1) / span : 0;
  r.p50_frame_ms = percentile(frame_ms, 0.5);
  r.p99_frame_ms = percentile(frame_ms, 0.99);
  return r;
}

Eigen::Vector3f colormap(double value, double lo, double hi) {
  if (!std::isfinite(value) || !(hi > lo)) return {0.5f, 0.5f, 0.5f};
  const auto lerp = [](const Eigen::Vector3f& a, const Eigen::Vector3f& b, double f) {
    return Eigen::Vector3f(a + float(f) * (b - a));
  };
  if (lo < 0 && hi > 0) {  // diverging about 0 (Moreland's cool-warm ends, white middle)
    const Eigen::Vector3f blue(0.23f, 0.30f, 0.75f), white(0.87f, 0.87f, 0.87f),
        red(0.71f, 0.02f, 0.15f);
    if (value < 0) return lerp(white, blue, std::min(1.0, value / lo));
    return lerp(white, red, std::min(1.0, value / hi));
  }
  // Sequential: five stops along viridis.
  static const Eigen::Vector3f stops[5] = {{0.267f, 0.005f, 0.329f},
                                           {0.231f, 0.322f, 0.545f},
                                           {0.129f, 0.569f, 0.549f},
                                           {0.369f, 0.788f, 0.384f},
                                           {0.993f, 0.906f, 0.144f}};
  const double f = std::clamp((value - lo) / (hi - lo), 0.0, 1.0) * 4;
  const int i = std::min(3, int(f));
  return lerp(stops[i], stops[i + 1], f - i);
}

void color_legend(const char* label, double lo, double hi) {
  ImGui::Text("%s", label);
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float width = 220, height = 14;
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const int n = 32;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3f c = colormap(lo + (hi - lo) * (i + 0.5) / n, lo, hi);
    draw->AddRectFilled(ImVec2(p.x + width * i / n, p.y),
                        ImVec2(p.x + width * (i + 1) / n, p.y + height),
                        ImGui::ColorConvertFloat4ToU32(ImVec4(c.x(), c.y(), c.z(), 1)));
  }
  ImGui::Dummy(ImVec2(width, height));
  ImGui::Text("%-12.3g%*s%12.3g", lo, 6, "", hi);
}

}  // namespace spinesim::viewer
