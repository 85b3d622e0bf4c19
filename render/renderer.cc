#include "render/renderer.h"

#include <fmt/format.h>

#include <stdexcept>

#include "render/gl.h"

namespace kinograph::render {

namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;
uniform mat4 u_model_view;
uniform mat4 u_projection;
uniform mat3 u_normal_matrix;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_color;
void main() {
  vec4 p = u_model_view * vec4(a_position, 1.0);
  v_position = p.xyz;
  v_normal = u_normal_matrix * a_normal;
  v_color = a_color;
  gl_Position = u_projection * p;
}
)";

// Blinn-Phong with a key and a fill light fixed relative to the camera; surfaces are lit from
// both sides because mesh files do not always wind their triangles consistently.
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_position;
in vec3 v_normal;
in vec4 v_color;
uniform vec4 u_color;
uniform int u_use_vertex_color;
uniform float u_alpha;
uniform vec4 u_light;  // ambient, key, fill, specular
out vec4 frag_color;
void main() {
  vec4 base = u_use_vertex_color != 0 ? v_color : u_color;
  vec3 n = normalize(v_normal);
  vec3 v = normalize(-v_position);
  if (dot(n, v) < 0.0) n = -n;
  vec3 key_dir = normalize(vec3(-0.45, 0.65, 0.6));
  vec3 fill_dir = normalize(vec3(0.7, -0.1, 0.5));
  float diffuse = u_light.x + u_light.y * max(dot(n, key_dir), 0.0)
                + u_light.z * max(dot(n, fill_dir), 0.0);
  float spec = u_light.w * pow(max(dot(n, normalize(key_dir + v)), 0.0), 40.0);
  frag_color = vec4(min(base.rgb * diffuse + vec3(spec), vec3(1.0)), base.a * u_alpha);
}
)";

unsigned compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw std::runtime_error(fmt::format("Renderer: shader compile failed: {}", log));
  }
  return shader;
}

}  // namespace

struct Renderer::GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  bool has_colors = false;
  Eigen::AlignedBox3d bounds;
};

Renderer::Renderer(const RendererOptions& options)
    : options_(options), context_(GlContextOptions{options.samples}) {
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  program_ = glCreateProgram();
  glAttachShader(program_, vs);
  glAttachShader(program_, fs);
  glLinkProgram(program_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) throw std::runtime_error("Renderer: shader program link failed");
  u_model_view_ = glGetUniformLocation(program_, "u_model_view");
  u_projection_ = glGetUniformLocation(program_, "u_projection");
  u_normal_matrix_ = glGetUniformLocation(program_, "u_normal_matrix");
  u_color_ = glGetUniformLocation(program_, "u_color");
  u_use_vertex_color_ = glGetUniformLocation(program_, "u_use_vertex_color");
  u_alpha_ = glGetUniformLocation(program_, "u_alpha");
  u_light_ = glGetUniformLocation(program_, "u_light");
}

Renderer::~Renderer() {
  context_.make_current();
  for (GpuMesh& m : meshes_) {
    glDeleteVertexArrays(1, &m.vao);
    glDeleteBuffers(1, &m.vbo);
    glDeleteBuffers(1, &m.ebo);
  }
  glDeleteProgram(program_);
}

MeshId Renderer::mesh(const std::string& key, const std::function<Mesh()>& make) {
  for (const auto& [k, id] : keys_) {
    if (k == key) return id;
  }
  return upload(key, make());
}

MeshId Renderer::upload(const std::string& key, const Mesh& mesh) {
  MeshId existing = -1;
  for (const auto& [k, id] : keys_) {
    if (k == key) existing = id;
  }
  if (existing >= 0) {
    GpuMesh& old = meshes_[existing];
    glDeleteVertexArrays(1, &old.vao);
    glDeleteBuffers(1, &old.vbo);
    glDeleteBuffers(1, &old.ebo);
  }
  GpuMesh gpu;
  gpu.index_count = static_cast<GLsizei>(mesh.indices.size());
  gpu.has_colors = mesh.has_colors;
  gpu.bounds = mesh.bounds();
  glGenVertexArrays(1, &gpu.vao);
  glBindVertexArray(gpu.vao);
  glGenBuffers(1, &gpu.vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gpu.vbo);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(Vertex)),
               mesh.vertices.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &gpu.ebo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gpu.ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, position)));
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, normal)));
  glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                        reinterpret_cast<void*>(offsetof(Vertex, color)));
  for (GLuint i = 0; i < 3; ++i) glEnableVertexAttribArray(i);
  glBindVertexArray(0);
  if (existing >= 0) {
    meshes_[existing] = gpu;
    return existing;
  }
  const auto id = static_cast<MeshId>(meshes_.size());
  meshes_.push_back(gpu);
  keys_.emplace_back(key, id);
  return id;
}

const Eigen::AlignedBox3d& Renderer::mesh_bounds(MeshId id) const { return meshes_.at(id).bounds; }

void Renderer::begin(int width, int height, const Eigen::Vector4f& background) {
  context_.make_current();
  context_.bind_target(width, height);
  height_ = height;
  glDisable(GL_SCISSOR_TEST);
  glClearColor(background[0], background[1], background[2], background[3]);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glUseProgram(program_);
  glUniform4f(u_light_, options_.ambient, options_.key, options_.fill, options_.specular);
}

void Renderer::set_panel(int x, int y, int w, int h, const Camera& camera) {
  const int gl_y = height_ - (y + h);  // GL viewports count rows from the bottom
  glViewport(x, gl_y, w, h);
  view_ = camera.view().cast<float>();
  const Eigen::Matrix4f projection = camera.projection(double(w) / h).cast<float>();
  glUniformMatrix4fv(u_projection_, 1, GL_FALSE, projection.data());
}

void Renderer::draw_items(const std::vector<DrawItem>& items, float alpha) {
  glUniform1f(u_alpha_, alpha);
  for (const DrawItem& item : items) {
    const GpuMesh& m = meshes_.at(item.mesh);
    Eigen::Matrix4d model = item.pose.matrix();
    model.topLeftCorner<3, 3>() *= item.scale.asDiagonal();
    const Eigen::Matrix4f model_view = view_ * model.cast<float>();
    const Eigen::Matrix3f normal_matrix = model_view.topLeftCorner<3, 3>().inverse().transpose();
    glUniformMatrix4fv(u_model_view_, 1, GL_FALSE, model_view.data());
    glUniformMatrix3fv(u_normal_matrix_, 1, GL_FALSE, normal_matrix.data());
    glUniform4fv(u_color_, 1, item.color.data());
    glUniform1i(u_use_vertex_color_, item.use_mesh_colors && m.has_colors ? 1 : 0);
    glBindVertexArray(m.vao);
    glDrawElements(GL_TRIANGLES, m.index_count, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
}

void Renderer::draw(const std::vector<DrawItem>& items) {
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  draw_items(items, 1.f);
}

void Renderer::draw_ghost(const std::vector<DrawItem>& items, float alpha) {
  // Pass 1: depth only, so that only the ghost's front-most surface receives colour.
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  draw_items(items, alpha);
  // Pass 2: blend the front-most surface over what is behind it.
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);  // keep dst alpha
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  draw_items(items, alpha);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
}

Image Renderer::finish() {
  glFinish();
  return context_.read_target();
}

}  // namespace kinograph::render
