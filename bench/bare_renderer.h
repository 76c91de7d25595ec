// The bare OpenGL program the benchmarks compare partsim's rasterizer with
// (partsim_render_bench, partsim_vision_dataset_bench): the same kind of EGL context, one VAO per
// mesh, one draw per instance with its MVP and colour, colour (RGBA float) and depth (float)
// targets read back with glReadPixels.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "partsim/render/backend.h"
#include "render/gl_util.h"

namespace partsim_bench {

using partsim::CameraParams;
using partsim::MeshData;
using partsim::RenderInstance;
using partsim::RenderWorld;

constexpr const char* kBareVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_mvp;
uniform mat3 u_normal_matrix;
out vec3 v_normal;
void main() {
  v_normal = u_normal_matrix * a_normal;
  gl_Position = u_mvp * vec4(a_position, 1.0);
}
)";

constexpr const char* kBareFragment = R"(#version 450 core
in vec3 v_normal;
uniform vec4 u_color;
layout(location = 0) out vec4 o_color;
void main() {
  float l = max(dot(normalize(v_normal), normalize(vec3(0.3, 0.5, 0.8))), 0.0);
  o_color = vec4(u_color.rgb * (0.2 + 0.8 * l), u_color.a);
}
)";

// the bare program shading like partsim: the same BRDF (Oren-Nayar diffuse, GGX specular with
// Smith-Schlick G and Schlick Fresnel), the bench's two lights (one directional, one point) and
// ambient, written here as a stand-alone program would be: no G-buffer inputs, no shadows
constexpr const char* kBarePbrVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_mvp;
uniform mat4 u_model_view;
uniform mat3 u_normal_matrix;
out vec3 v_position;
out vec3 v_normal;
void main() {
  v_position = (u_model_view * vec4(a_position, 1.0)).xyz;
  v_normal = u_normal_matrix * a_normal;
  gl_Position = u_mvp * vec4(a_position, 1.0);
}
)";

constexpr const char* kBarePbrFragment = R"(#version 450 core
in vec3 v_position;
in vec3 v_normal;
uniform vec4 u_color;
uniform float u_roughness;
uniform float u_metallic;
uniform vec3 u_sun_direction;  // camera frame, where the light travels
uniform vec3 u_sun_color;
uniform vec3 u_lamp_position;  // camera frame
uniform vec3 u_lamp_color;
uniform vec3 u_ambient;
layout(location = 0) out vec4 o_color;
const float PI = 3.14159265358979;
vec3 Brdf(vec3 n, vec3 v, vec3 l, vec3 albedo, float r, float m) {
  float nl = dot(n, l);
  if (nl <= 0.0) return vec3(0.0);
  float nv = max(dot(n, v), 1e-4);
  vec3 h = normalize(l + v);
  float nh = max(dot(n, h), 0.0), vh = max(dot(v, h), 0.0);
  vec3 f0 = mix(vec3(0.04), albedo, m);
  vec3 f = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
  float a2 = r * r * r * r, k = 0.5 * r * r;
  float q = nh * nh * (a2 - 1.0) + 1.0;
  float g = nl / (nl * (1.0 - k) + k) * nv / (nv * (1.0 - k) + k);
  vec3 spec = f * (a2 / (PI * q * q) * g / (4.0 * nl * nv));
  float s2 = r * r, t = dot(l, v) - nl * nv;
  float on = 1.0 - 0.5 * s2 / (s2 + 0.33) + (t > 0.0 ? 0.45 * s2 / (s2 + 0.09) * t / max(nl, nv) : 0.0);
  return ((1.0 - f) * (1.0 - m) * albedo / PI * on + spec) * nl;
}
void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(-v_position);
  float r = clamp(u_roughness, 0.05, 1.0), m = clamp(u_metallic, 0.0, 1.0);
  vec3 albedo = u_color.rgb;
  vec3 c = albedo * u_ambient * (1.0 - m) + mix(vec3(0.04), albedo, m) * u_ambient * m;
  c += Brdf(n, v, -u_sun_direction, albedo, r, m) * u_sun_color;
  vec3 d = u_lamp_position - v_position;
  float dist2 = max(dot(d, d), 1e-12);
  c += Brdf(n, v, d * inversesqrt(dist2), albedo, r, m) * u_lamp_color / dist2;
  o_color = vec4(clamp(c, 0.0, 1.0), 1.0);
}
)";

class BareRenderer {
 public:
  // pbr: shade like partsim (kBarePbr*) rather than with one Lambert term
  explicit BareRenderer(bool pbr = false) : pbr_(pbr) {
    program_ = partsim::internal::BuildProgram("bare", pbr ? kBarePbrVertex : kBareVertex, "bench",
                                               pbr ? kBarePbrFragment : kBareFragment, "bench");
    mvp_ = glGetUniformLocation(program_, "u_mvp");
    normal_matrix_ = glGetUniformLocation(program_, "u_normal_matrix");
    color_ = glGetUniformLocation(program_, "u_color");
    for (const char* name : {"u_model_view", "u_roughness", "u_metallic", "u_sun_direction",
                             "u_sun_color", "u_lamp_position", "u_lamp_color", "u_ambient"}) {
      pbr_locations_.push_back(glGetUniformLocation(program_, name));
    }
  }

  // pbr as above, with the meshes of `world` uploaded
  BareRenderer(const RenderWorld& world, bool pbr) : BareRenderer(pbr) { Load(world); }

  BareRenderer(const BareRenderer&) = delete;
  BareRenderer& operator=(const BareRenderer&) = delete;

  // uploads the meshes of `world` (replacing those of the last world)
  void Load(const RenderWorld& world) {
    context_.MakeCurrent();
    ClearMeshes();
    for (const RenderInstance& inst : world.instances) {
      const MeshData* key = inst.mesh.get();
      if (std::find_if(meshes_.begin(), meshes_.end(),
                       [&](const Mesh& m) { return m.key == key; }) != meshes_.end()) {
        continue;
      }
      meshes_.push_back(Upload(*inst.mesh));
    }
  }

  ~BareRenderer() {
    context_.MakeCurrent();
    ClearMeshes();
    glDeleteFramebuffers(1, &fbo_);
    glDeleteTextures(1, &color_tex_);
    glDeleteTextures(1, &depth_tex_);
    glDeleteProgram(program_);
  }

  void Render(const RenderWorld& world, const CameraParams& cam, std::vector<float>* color,
              std::vector<float>* depth) {
    context_.MakeCurrent();
    Resize(cam.width, cam.height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, cam.width, cam.height);
    const float zeros[4] = {0, 0, 0, 0}, one = 1;
    glClearNamedFramebufferfv(fbo_, GL_COLOR, 0, zeros);
    glClearNamedFramebufferfv(fbo_, GL_DEPTH, 0, &one);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glUseProgram(program_);
    if (pbr_) SetLights(world, cam);
    Eigen::Matrix4d view_proj = cam.projection * cam.view;
    for (const RenderInstance& inst : world.instances) {
      const Mesh* mesh = nullptr;
      for (const Mesh& m : meshes_) {
        if (m.key == inst.mesh.get()) mesh = &m;
      }
      Eigen::Matrix4f mvp = (view_proj * inst.X_WV).cast<float>();
      Eigen::Matrix3f nm =
          (cam.view * inst.X_WV).topLeftCorner<3, 3>().inverse().transpose().cast<float>();
      glUniformMatrix4fv(mvp_, 1, GL_FALSE, mvp.data());
      glUniformMatrix3fv(normal_matrix_, 1, GL_FALSE, nm.data());
      glUniform4fv(color_, 1, inst.material.base_color.data());
      if (pbr_) {
        Eigen::Matrix4f mv = (cam.view * inst.X_WV).cast<float>();
        glUniformMatrix4fv(pbr_locations_[0], 1, GL_FALSE, mv.data());
        glUniform1f(pbr_locations_[1], inst.material.roughness);
        glUniform1f(pbr_locations_[2], inst.material.metallic);
      }
      glBindVertexArray(mesh->vao);
      glDrawElements(GL_TRIANGLES, mesh->count, GL_UNSIGNED_INT, nullptr);
    }
    size_t n = static_cast<size_t>(cam.width) * cam.height;
    color->resize(4 * n);
    depth->resize(n);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, cam.width, cam.height, GL_RGBA, GL_FLOAT, color->data());
    glReadPixels(0, 0, cam.width, cam.height, GL_DEPTH_COMPONENT, GL_FLOAT, depth->data());
  }

 private:
  // the scene's directional and point light (AddLights) and ambient, in the camera frame
  void SetLights(const RenderWorld& world, const CameraParams& cam) {
    Eigen::Matrix3d R = cam.view.topLeftCorner<3, 3>();
    for (const partsim::LightDesc& light : world.lights) {
      if (light.type == partsim::LightType::kDirectional) {
        Eigen::Vector3f d = (R * light.direction.normalized()).cast<float>();
        glUniform3fv(pbr_locations_[3], 1, d.data());
        glUniform3fv(pbr_locations_[4], 1, light.color.data());
      } else {
        Eigen::Vector3f p = (cam.view * light.position.homogeneous()).head<3>().cast<float>();
        glUniform3fv(pbr_locations_[5], 1, p.data());
        glUniform3fv(pbr_locations_[6], 1, light.color.data());
      }
    }
    glUniform3fv(pbr_locations_[7], 1, world.ambient.data());
  }

  void ClearMeshes() {
    for (Mesh& m : meshes_) {
      glDeleteVertexArrays(1, &m.vao);
      glDeleteBuffers(1, &m.vbo);
      glDeleteBuffers(1, &m.ebo);
    }
    meshes_.clear();
  }

  struct Mesh {
    const MeshData* key = nullptr;
    GLuint vao = 0, vbo = 0, ebo = 0;
    GLsizei count = 0;
  };

  Mesh Upload(const MeshData& data) {
    // flat normals when the mesh has none, as partsim does
    std::vector<float> v;
    std::vector<uint32_t> idx;
    bool smooth = data.normals.size() == data.vertices.size();
    if (smooth) {
      for (size_t i = 0; i < data.vertices.size(); ++i) {
        v.insert(v.end(), data.vertices[i].data(), data.vertices[i].data() + 3);
        v.insert(v.end(), data.normals[i].data(), data.normals[i].data() + 3);
      }
      for (const auto& f : data.faces)
        idx.insert(idx.end(), {uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
    } else {
      for (const auto& f : data.faces) {
        Eigen::Vector3f n = (data.vertices[f[1]] - data.vertices[f[0]])
                                .cross(data.vertices[f[2]] - data.vertices[f[0]])
                                .normalized();
        for (int k = 0; k < 3; ++k) {
          idx.push_back(static_cast<uint32_t>(v.size() / 6));
          v.insert(v.end(), data.vertices[f[k]].data(), data.vertices[f[k]].data() + 3);
          v.insert(v.end(), n.data(), n.data() + 3);
        }
      }
    }
    Mesh m;
    m.key = &data;
    m.count = static_cast<GLsizei>(idx.size());
    glCreateBuffers(1, &m.vbo);
    glNamedBufferStorage(m.vbo, v.size() * sizeof(float), v.data(), 0);
    glCreateBuffers(1, &m.ebo);
    glNamedBufferStorage(m.ebo, idx.size() * sizeof(uint32_t), idx.data(), 0);
    glCreateVertexArrays(1, &m.vao);
    glVertexArrayVertexBuffer(m.vao, 0, m.vbo, 0, 6 * sizeof(float));
    glVertexArrayElementBuffer(m.vao, m.ebo);
    for (GLuint a = 0; a < 2; ++a) {
      glEnableVertexArrayAttrib(m.vao, a);
      glVertexArrayAttribFormat(m.vao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
      glVertexArrayAttribBinding(m.vao, a, 0);
    }
    return m;
  }

  void Resize(int w, int h) {
    if (w == width_ && h == height_) return;
    glDeleteFramebuffers(1, &fbo_);
    glDeleteTextures(1, &color_tex_);
    glDeleteTextures(1, &depth_tex_);
    glCreateTextures(GL_TEXTURE_2D, 1, &color_tex_);
    glTextureStorage2D(color_tex_, 1, GL_RGBA32F, w, h);
    glCreateTextures(GL_TEXTURE_2D, 1, &depth_tex_);
    glTextureStorage2D(depth_tex_, 1, GL_DEPTH_COMPONENT32F, w, h);
    glCreateFramebuffers(1, &fbo_);
    glNamedFramebufferTexture(fbo_, GL_COLOR_ATTACHMENT0, color_tex_, 0);
    glNamedFramebufferTexture(fbo_, GL_DEPTH_ATTACHMENT, depth_tex_, 0);
    width_ = w;
    height_ = h;
  }

  partsim::internal::EglContext context_;  // constructed (and current) before the GL calls
  bool pbr_ = false;
  GLuint program_ = 0;
  GLint mvp_ = -1, normal_matrix_ = -1, color_ = -1;
  std::vector<GLint> pbr_locations_;
  std::vector<Mesh> meshes_;
  GLuint fbo_ = 0, color_tex_ = 0, depth_tex_ = 0;
  int width_ = 0, height_ = 0;
};

}  // namespace partsim_bench
