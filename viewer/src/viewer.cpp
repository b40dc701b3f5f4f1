#include "spinesim/viewer/viewer.hpp"

#include <GL/glcorearb.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <stb_image_write.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace spinesim::viewer {

namespace {

constexpr float kPi = 3.14159265358979f;

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 model, view, projection;
out vec3 eye_normal;
void main() {
  mat4 mv = view * model;
  eye_normal = mat3(mv) * normal;
  gl_Position = projection * mv * vec4(position, 1.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec3 eye_normal;
uniform vec3 color;
out vec4 fragment;
void main() {
  // A headlight: the light comes from the eye; both faces lit (open or inward-facing surfaces).
  float d = abs(normalize(eye_normal).z);
  fragment = vec4(color * (0.25 + 0.75 * d), 1.0);
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

/// One body on the GPU: flat-shaded triangles (three vertices each, with the face normal).
struct GpuMesh {
  GLuint vao = 0, vbo = 0;
  GLsizei vertices = 0;
};

GpuMesh upload(const Body& b) {
  std::vector<float> data;
  data.reserve(std::size_t(b.F.rows()) * 18);
  for (Eigen::Index f = 0; f < b.F.rows(); ++f) {
    const Eigen::Vector3d a = b.V.row(b.F(f, 0)), c1 = b.V.row(b.F(f, 1)), c2 = b.V.row(b.F(f, 2));
    Eigen::Vector3d n = (c1 - a).cross(c2 - a);
    n = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitY();
    for (const Eigen::Vector3d& p : {a, c1, c2})
      for (const double v : {p.x(), p.y(), p.z(), n.x(), n.y(), n.z()}) data.push_back(float(v));
  }
  GpuMesh m;
  m.vertices = GLsizei(data.size() / 6);
  glGenVertexArrays(1, &m.vao);
  glGenBuffers(1, &m.vbo);
  glBindVertexArray(m.vao);
  glBindBuffer(GL_ARRAY_BUFFER, m.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(),
               GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                        reinterpret_cast<void*>(3 * sizeof(float)));
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  return m;
}

/// Orbit camera about a target: yaw about the superior (y) axis, pitch above the horizontal.
struct Camera {
  Eigen::Vector3f target = Eigen::Vector3f::Zero();
  float distance = 1000, yaw = 0, pitch = 0.1f, fov = 35.0f * kPi / 180.0f;

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
    yaw = 0;  // the eye on the body's right (-x): a sagittal view, anterior to the screen's right
    pitch = 0.1f;
  }
};

/// Mouse: left drag orbits, right drag pans, the wheel zooms (unless ImGui wants the mouse).
struct Mouse {
  double x = 0, y = 0;
  bool left = false, right = false;
};

void handle_input(GLFWwindow* w, Camera& cam, Mouse& mouse) {
  double x = 0, y = 0;
  glfwGetCursorPos(w, &x, &y);
  const bool want = ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse;
  const bool left = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && !want;
  const bool right = glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS && !want;
  const float dx = float(x - mouse.x), dy = float(y - mouse.y);
  if (left && mouse.left) {
    cam.yaw += 0.005f * dx;
    cam.pitch = std::clamp(cam.pitch + 0.005f * dy, -1.5f, 1.5f);
  }
  if (right && mouse.right) {
    const Eigen::Matrix4f v = cam.view();
    const float scale = cam.distance * 0.0015f;
    cam.target +=
        scale * (-dx * v.block<1, 3>(0, 0).transpose() + dy * v.block<1, 3>(1, 0).transpose());
  }
  mouse = {x, y, left, right};
}

double scroll_accumulated = 0;
void on_scroll(GLFWwindow*, double, double dy) { scroll_accumulated += dy; }

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

}  // namespace

void check(const ViewOptions& o) {
  if (o.width < 64 || o.height < 64 || o.width > 8192 || o.height > 8192)
    throw std::invalid_argument("view: the window must be 64 to 8192 pixels each way");
  if (!o.screenshot.empty() && o.frames < 1)
    throw std::invalid_argument("view: --frames must be at least 1");
}

ViewResult view(const std::vector<Body>& bodies, const ViewOptions& o) {
  if (bodies.empty()) throw std::invalid_argument("view: nothing to show (no bodies)");
  check(o);
  GLFWwindow* w = open_window(o);
  glfwSetScrollCallback(w, on_scroll);
  ViewResult r;
  r.renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  r.gl_version = reinterpret_cast<const char*>(glGetString(GL_VERSION));

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left behind
  ImGui_ImplGlfw_InitForOpenGL(w, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  const GLuint program = link_program();
  std::vector<GpuMesh> meshes;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  long triangles = 0;
  for (const Body& b : bodies) {
    meshes.push_back(upload(b));
    triangles += long(b.F.rows());
    for (Eigen::Index i = 0; i < b.V.rows(); ++i) {
      const Eigen::Vector3d p = b.R * b.V.row(i).transpose() + b.t;
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    }
  }
  Camera cam;
  const auto reset = [&] {
    cam.frame((0.5 * (lo + hi)).cast<float>(), float(0.5 * (hi - lo).norm()));
  };
  reset();
  Mouse mouse;
  glEnable(GL_DEPTH_TEST);

  const auto start = std::chrono::steady_clock::now();
  while (!glfwWindowShouldClose(w)) {
    glfwPollEvents();
    handle_input(w, cam, mouse);
    cam.distance *= float(std::pow(0.9, scroll_accumulated));
    scroll_accumulated = 0;
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(w, &fw, &fh);
    glViewport(0, 0, fw, fh);
    glClearColor(0.12f, 0.13f, 0.15f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glUseProgram(program);
    const Eigen::Matrix4f view = cam.view(),
                          proj = cam.projection(float(fw) / float(std::max(fh, 1)));
    glUniformMatrix4fv(glGetUniformLocation(program, "view"), 1, GL_FALSE, view.data());
    glUniformMatrix4fv(glGetUniformLocation(program, "projection"), 1, GL_FALSE, proj.data());
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      Eigen::Matrix4f model = Eigen::Matrix4f::Identity();
      model.topLeftCorner<3, 3>() = bodies[i].R.cast<float>();
      model.topRightCorner<3, 1>() = bodies[i].t.cast<float>();
      glUniformMatrix4fv(glGetUniformLocation(program, "model"), 1, GL_FALSE, model.data());
      glUniform3fv(glGetUniformLocation(program, "color"), 1, bodies[i].color.data());
      glBindVertexArray(meshes[i].vao);
      glDrawArrays(GL_TRIANGLES, 0, meshes[i].vertices);
    }
    if (o.panel) {
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_Once);
      ImGui::Begin("spinesim");
      ImGui::Text("%d bodies, %ld triangles", int(bodies.size()), triangles);
      ImGui::Text("frame %.1f ms", 1000.0 / std::max(1e-3, double(ImGui::GetIO().Framerate)));
      ImGui::Text("%s", r.renderer.c_str());
      if (ImGui::Button("reset camera")) reset();
      ImGui::TextDisabled("left drag: orbit, right drag: pan, wheel: zoom");
      ImGui::End();
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }
    ++r.frames;
    if (!o.screenshot.empty() && r.frames >= o.frames) {
      write_png(o.screenshot, fw, fh);
      break;
    }
    glfwSwapBuffers(w);
  }
  r.mean_frame_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() /
      std::max(1, r.frames);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  for (GpuMesh& m : meshes) {
    glDeleteBuffers(1, &m.vbo);
    glDeleteVertexArrays(1, &m.vao);
  }
  glDeleteProgram(program);
  glfwDestroyWindow(w);
  glfwTerminate();
  return r;
}

}  // namespace spinesim::viewer
