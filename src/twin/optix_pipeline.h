#pragma once
// The twin's OptiX context, module (programs.cu as OptiX-IR), pipeline and
// shader binding tables: one SBT per raygen program, the hit groups of the
// two ray types shared by every BLAS (all instances use SBT offset 0).
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "accretion/scene/settings.h"
#include "device_buffer.h"

namespace accretion::twin {

/// gbuffer: primary rays; exact: the exact estimator; sample: the uniform
/// and power estimators; shade: restir's
/// traceShadowRays with optixTrace (pipeline); shadeTraverse: the same with
/// optixTraverse and a hit object (the inline-like path), optionally after
/// optixReorder (SER).
enum class Raygen { gbuffer, exact, sample, shade, shadeTraverse, resampleParticlePixels, updateVoxelCache, shadeSplitTexels, count };

class TwinPipeline {
public:
    /// programs: the OptiX-IR file built from programs.cu; opacityMicromaps:
    /// the BLAS may carry opacity micromaps; layout and spheres pick the hit
    /// groups' intersection (triangles, the billboard intersection program,
    /// or OptiX's built-in spheres, whose module takes the BLAS build flags).
    TwinPipeline(const std::filesystem::path& programs, bool validation, bool opacityMicromaps, AccelLayout layout,
                 bool spheres, unsigned sphereBuildFlags);
    ~TwinPipeline();
    TwinPipeline(const TwinPipeline&) = delete;
    TwinPipeline& operator=(const TwinPipeline&) = delete;

    OptixDeviceContext context() const { return context_; }
    /// What the device reports of its ray-tracing hardware: the RT core
    /// version (0: none, traversal in software), SER and cluster
    /// acceleration structure support.
    nlohmann::json deviceProperties() const;
    /// Launch raygen `r` over width x height with the params at `params` (device).
    void launch(Raygen r, CUdeviceptr params, std::size_t paramsBytes, unsigned width, unsigned height,
                cudaStream_t stream) const;

private:
    /// The constructor's steps: the module (and the built-in sphere module),
    /// the program groups, the linked pipeline, the shader binding tables.
    void createModules(const std::filesystem::path& programs, const OptixPipelineCompileOptions& pipelineOptions, bool spheres,
                       unsigned sphereBuildFlags);
    void createProgramGroups(AccelLayout layout, bool spheres);
    void linkPipeline(const OptixPipelineCompileOptions& pipelineOptions);
    void buildShaderBindingTables();

    OptixDeviceContext context_ = nullptr;
    OptixModule module_ = nullptr, sphereModule_ = nullptr;
    OptixProgramGroup raygen_[int(Raygen::count)] = {};
    OptixProgramGroup miss_ = nullptr, hitPrimary_ = nullptr, hitShadow_ = nullptr;
    OptixPipeline pipeline_ = nullptr;
    DeviceBuffer raygenRecords_, missRecords_, hitRecords_;
    OptixShaderBindingTable sbt_[int(Raygen::count)] = {};
};

}  // namespace accretion::twin
