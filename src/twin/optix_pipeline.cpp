#include "optix_pipeline.h"

#include <fstream>
#include <iterator>
#include <vector>

#include <fmt/format.h>
#include <optix_function_table_definition.h>
#include <optix_stack_size.h>
#include <optix_stubs.h>

#include "launch_params.h"

namespace accretion::twin {
namespace {

struct alignas(OPTIX_SBT_RECORD_ALIGNMENT) EmptyRecord {
    char header[OPTIX_SBT_RECORD_HEADER_SIZE];
};

std::string readBinary(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw GpuError(fmt::format("{}: cannot open the OptiX programs (built with accretion-optix)", file.string()));
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void logCallback(unsigned level, const char* tag, const char* message, void*) {
    if (level <= 2) fmt::print(stderr, "optix [{}] {}: {}\n", level, tag, message);
}

}  // namespace

TwinPipeline::TwinPipeline(const std::filesystem::path& programs, bool validation, bool opacityMicromaps, AccelLayout layout,
                           bool spheres, unsigned sphereBuildFlags) {
    CUDA_CHECK(cudaFree(nullptr));  // the primary context
    OPTIX_CHECK(optixInit());
    OptixDeviceContextOptions options{};
    options.logCallbackFunction = &logCallback;
    options.logCallbackLevel = 4;
    if (validation) options.validationMode = OPTIX_DEVICE_CONTEXT_VALIDATION_MODE_ALL;
    OPTIX_CHECK(optixDeviceContextCreate(nullptr, &options, &context_));

    OptixPipelineCompileOptions pipelineOptions{};
    pipelineOptions.usesMotionBlur = 0;
    pipelineOptions.traversableGraphFlags = OPTIX_TRAVERSABLE_GRAPH_FLAG_ALLOW_SINGLE_LEVEL_INSTANCING;
    pipelineOptions.numPayloadValues = 5;
    pipelineOptions.numAttributeValues = 2;
    pipelineOptions.exceptionFlags = OPTIX_EXCEPTION_FLAG_NONE;
    pipelineOptions.pipelineLaunchParamsVariableName = "params";
    pipelineOptions.usesPrimitiveTypeFlags = spheres                           ? OPTIX_PRIMITIVE_TYPE_FLAGS_SPHERE
                                             : layout == AccelLayout::aabbs ? OPTIX_PRIMITIVE_TYPE_FLAGS_CUSTOM
                                                                            : OPTIX_PRIMITIVE_TYPE_FLAGS_TRIANGLE;
    pipelineOptions.allowOpacityMicromaps = opacityMicromaps ? 1 : 0;
    createModules(programs, pipelineOptions, spheres, sphereBuildFlags);
    createProgramGroups(layout, spheres);
    linkPipeline(pipelineOptions);
    buildShaderBindingTables();
}

void TwinPipeline::createModules(const std::filesystem::path& programs, const OptixPipelineCompileOptions& pipelineOptions,
                                 bool spheres, unsigned sphereBuildFlags) {
    OptixModuleCompileOptions moduleOptions{};
    moduleOptions.optLevel = OPTIX_COMPILE_OPTIMIZATION_DEFAULT;
    moduleOptions.debugLevel = OPTIX_COMPILE_DEBUG_LEVEL_MINIMAL;
    const std::string ir = readBinary(programs);
    char log[4096];
    size_t logSize = sizeof log;
    OPTIX_CHECK(optixModuleCreate(context_, &moduleOptions, &pipelineOptions, ir.data(), ir.size(), log, &logSize, &module_));
    if (spheres) {
        OptixBuiltinISOptions builtin{};
        builtin.builtinISModuleType = OPTIX_PRIMITIVE_TYPE_SPHERE;
        builtin.buildFlags = sphereBuildFlags;
        OPTIX_CHECK(optixBuiltinISModuleGet(context_, &moduleOptions, &pipelineOptions, &builtin, &sphereModule_));
    }
}

void TwinPipeline::createProgramGroups(AccelLayout layout, bool spheres) {
    auto group = [&](const OptixProgramGroupDesc& desc) {
        OptixProgramGroupOptions groupOptions{};
        OptixProgramGroup g = nullptr;
        char log[4096];
        size_t size = sizeof log;
        OPTIX_CHECK(optixProgramGroupCreate(context_, &desc, 1, &groupOptions, log, &size, &g));
        return g;
    };
    const char* raygenNames[] = {"__raygen__gbuffer", "__raygen__exact", "__raygen__sample", "__raygen__shade",
                                 "__raygen__shadeTraverse", "__raygen__resampleParticlePixels", "__raygen__updateVoxelCache",
                                 "__raygen__shadeSplitTexels"};
    static_assert(std::size(raygenNames) == std::size_t(Raygen::count), "a name for every raygen");
    for (int r = 0; r < int(Raygen::count); ++r) {
        OptixProgramGroupDesc d{};
        d.kind = OPTIX_PROGRAM_GROUP_KIND_RAYGEN;
        d.raygen.module = module_;
        d.raygen.entryFunctionName = raygenNames[r];
        raygen_[r] = group(d);
    }
    {
        OptixProgramGroupDesc d{};
        d.kind = OPTIX_PROGRAM_GROUP_KIND_MISS;
        d.miss.module = module_;
        d.miss.entryFunctionName = "__miss__none";
        miss_ = group(d);
    }
    auto hitGroup = [&](const char* closestHit, const char* anyHit) {
        OptixProgramGroupDesc d{};
        d.kind = OPTIX_PROGRAM_GROUP_KIND_HITGROUP;
        d.hitgroup.moduleCH = closestHit ? module_ : nullptr;
        d.hitgroup.entryFunctionNameCH = closestHit;
        d.hitgroup.moduleAH = module_;
        d.hitgroup.entryFunctionNameAH = anyHit;
        if (spheres) {
            d.hitgroup.moduleIS = sphereModule_;  // built-in: no entry function
        } else if (layout == AccelLayout::aabbs) {
            d.hitgroup.moduleIS = module_;
            d.hitgroup.entryFunctionNameIS = "__intersection__billboard";
        }
        return group(d);
    };
    hitPrimary_ = hitGroup("__closesthit__primary", "__anyhit__primary");
    hitShadow_ = hitGroup("__closesthit__shadow", "__anyhit__shadow");
}

void TwinPipeline::linkPipeline(const OptixPipelineCompileOptions& pipelineOptions) {
    std::vector<OptixProgramGroup> all(std::begin(raygen_), std::end(raygen_));
    all.insert(all.end(), {miss_, hitPrimary_, hitShadow_});
    OptixPipelineLinkOptions linkOptions{};
    linkOptions.maxTraceDepth = 1;
    char log[4096];
    size_t logSize = sizeof log;
    OPTIX_CHECK(optixPipelineCreate(context_, &pipelineOptions, &linkOptions, all.data(), unsigned(all.size()), log,
                                    &logSize, &pipeline_));
    OptixStackSizes stack{};
    for (OptixProgramGroup g : all) OPTIX_CHECK(optixUtilAccumulateStackSizes(g, &stack, pipeline_));
    unsigned fromTraversal = 0, fromState = 0, continuation = 0;
    OPTIX_CHECK(optixUtilComputeStackSizes(&stack, 1, 0, 0, &fromTraversal, &fromState, &continuation));
    OPTIX_CHECK(optixPipelineSetStackSize(pipeline_, fromTraversal, fromState, continuation, 2));
}

void TwinPipeline::buildShaderBindingTables() {
    // Records: no data, headers only.
    std::vector<EmptyRecord> rg(int(Raygen::count)), ms(kRayTypes), hg(kRayTypes);
    for (int r = 0; r < int(Raygen::count); ++r) OPTIX_CHECK(optixSbtRecordPackHeader(raygen_[r], &rg[r]));
    for (auto& m : ms) OPTIX_CHECK(optixSbtRecordPackHeader(miss_, &m));
    OPTIX_CHECK(optixSbtRecordPackHeader(hitPrimary_, &hg[kPrimaryRay]));
    OPTIX_CHECK(optixSbtRecordPackHeader(hitShadow_, &hg[kShadowRay]));
    raygenRecords_.upload(rg);
    missRecords_.upload(ms);
    hitRecords_.upload(hg);
    for (int r = 0; r < int(Raygen::count); ++r) {
        OptixShaderBindingTable& s = sbt_[r];
        s.raygenRecord = raygenRecords_.address() + r * sizeof(EmptyRecord);
        s.missRecordBase = missRecords_.address();
        s.missRecordStrideInBytes = sizeof(EmptyRecord);
        s.missRecordCount = kRayTypes;
        s.hitgroupRecordBase = hitRecords_.address();
        s.hitgroupRecordStrideInBytes = sizeof(EmptyRecord);
        s.hitgroupRecordCount = kRayTypes;
    }
}

TwinPipeline::~TwinPipeline() {
    if (pipeline_) optixPipelineDestroy(pipeline_);
    for (OptixProgramGroup g : raygen_)
        if (g) optixProgramGroupDestroy(g);
    for (OptixProgramGroup g : {miss_, hitPrimary_, hitShadow_})
        if (g) optixProgramGroupDestroy(g);
    if (module_) optixModuleDestroy(module_);
    if (sphereModule_) optixModuleDestroy(sphereModule_);
    if (context_) optixDeviceContextDestroy(context_);
}

nlohmann::json TwinPipeline::deviceProperties() const {
    auto property = [&](OptixDeviceProperty p) {
        unsigned value = 0;
        OPTIX_CHECK(optixDeviceContextGetProperty(context_, p, &value, sizeof value));
        return value;
    };
    return {{"rtcore_version", property(OPTIX_DEVICE_PROPERTY_RTCORE_VERSION)},
            {"shader_execution_reordering", property(OPTIX_DEVICE_PROPERTY_SHADER_EXECUTION_REORDERING)},
            {"cluster_accel", property(OPTIX_DEVICE_PROPERTY_CLUSTER_ACCEL)}};
}

void TwinPipeline::launch(Raygen r, CUdeviceptr params, std::size_t paramsBytes, unsigned width, unsigned height,
                           cudaStream_t stream) const {
    OPTIX_CHECK(optixLaunch(pipeline_, stream, params, paramsBytes, &sbt_[int(r)], width, height, 1));
}

}  // namespace accretion::twin
