// A C++ program of someone else's: the installed header compiles as C++, the library links, and the
// library that runs is the version the program was compiled against. The built-in scene's light fully
// lights an open point of the ground and none of it reaches a point inside the cube (consumer.c says why).
#include <microshadow.h>
#include <cstdio>
#include <string>
#include <vector>

int main()
{
    int major = -1, minor = -1, patch = -1;
    const std::string running = ms_version(&major, &minor, &patch);
    if (running != MS_VERSION_STRING || major != MS_VERSION_MAJOR || minor != MS_VERSION_MINOR ||
        patch != MS_VERSION_PATCH) {
        std::fprintf(stderr, "consumer_cxx: compiled against %s, running %s\n", MS_VERSION_STRING, running.c_str());
        return 1;
    }
    char err[512];
    ms_scene sc;
    if (ms_scene_default(&sc) != 0) { std::fprintf(stderr, "consumer_cxx: no default scene\n"); return 1; }
    ms_accel *acc = nullptr;
    if (ms_accel_build(&sc, 0, &acc, err, sizeof err) != MS_OK) { std::fprintf(stderr, "consumer_cxx: %s\n", err); return 1; }
    const std::vector<float> pos = { 5.0f, 0.0f, 5.0f, 2.25f, 0.5f, -0.75f };
    const std::vector<float> nor = { 0, 1, 0, 0, 1, 0 };
    ms_points pts = { 2, pos.data(), nor.data(), nullptr, nullptr };
    std::vector<float> v(2), s(2);
    const ms_status st = ms_visibility_points(acc, nullptr, &pts, nullptr, v.data(), s.data(), nullptr, nullptr, err, sizeof err);
    ms_accel_free(acc);
    ms_scene_free(&sc);
    if (st != MS_OK) { std::fprintf(stderr, "consumer_cxx: %s: %s\n", ms_status_name(st), err); return 1; }
    std::printf("C++: microshadow %s, V open %.4f, inside the cube %.4f\n", running.c_str(), v[0], v[1]);
    return v[0] == 1.0f && v[1] == 0.0f ? 0 : 1;
}
