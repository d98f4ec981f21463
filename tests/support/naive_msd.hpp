// A deliberately naive mass-spring-damper model, written the way the thesis's code is
// (its Código 4.1-4.4): heap-allocated Mass and Spring objects reached through pointers, an
// array-of-structs Vector3D, springs found with a std::set of vertex pairs. It shares no code
// with the library, so it serves twice: as an independent reference for the dynamics tests
// and as the baseline of the step benchmark. Same physics as flexfit::stepFullModel with no
// restoration: semi-implicit Euler, spring damping along the spring axis, global damping.
#pragma once

#include <cmath>
#include <set>
#include <utility>
#include <vector>

namespace naive {

struct Vector3D {
    double x = 0, y = 0, z = 0;
    Vector3D() = default;
    Vector3D(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
    Vector3D operator+(const Vector3D& o) const { return {x + o.x, y + o.y, z + o.z}; }
    Vector3D operator-(const Vector3D& o) const { return {x - o.x, y - o.y, z - o.z}; }
    Vector3D operator*(double s) const { return {x * s, y * s, z * s}; }
    Vector3D operator/(double s) const { return {x / s, y / s, z / s}; }
    Vector3D operator-() const { return {-x, -y, -z}; }
    Vector3D& operator+=(const Vector3D& o) { x += o.x; y += o.y; z += o.z; return *this; }
    double dot(const Vector3D& o) const { return x * o.x + y * o.y + z * o.z; }
    double length() const { return std::sqrt(x * x + y * y + z * z); }
};

class Mass {
public:
    explicit Mass(double m) : mass(m) {}
    double mass;
    Vector3D position, velocity, force;
    int anchor = 0;
    Vector3D fixedPosition;
    void init() { force = Vector3D(); }
    void applyForce(const Vector3D& f) { force += f; }
    void simulate(double dt) {
        velocity += (force / mass) * dt;
        position += velocity * dt;
    }
};

class Spring {
public:
    Spring(Mass* a, Mass* b, double k, double length, double friction)
        : mass1(a), mass2(b), springConstant(k), springLength(length), frictionConstant(friction) {}
    Mass* mass1;
    Mass* mass2;
    double springConstant, springLength, frictionConstant;
    void solve() {
        const Vector3D springVector = mass1->position - mass2->position;
        const double r = springVector.length();
        if (r == 0) return;
        const Vector3D u = springVector / r;
        const double relative = (mass1->velocity - mass2->velocity).dot(u);
        const Vector3D force = -u * (springConstant * (r - springLength) + frictionConstant * relative);
        mass1->applyForce(force);
        mass2->applyForce(-force);
    }
};

class Model {
public:
    // vertices: x y z triples; faces: a b c triples.
    Model(const std::vector<double>& vertices, const std::vector<unsigned>& faces, double massValue, double k, double b)
        : numOfMasses(int(vertices.size() / 3)) {
        masses = new Mass*[numOfMasses];
        for (int i = 0; i < numOfMasses; i++) {
            masses[i] = new Mass(massValue);
            masses[i]->position = Vector3D(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
            masses[i]->fixedPosition = masses[i]->position;
        }
        std::set<std::pair<unsigned, unsigned>> unique;
        for (std::size_t f = 0; f + 2 < faces.size(); f += 3)
            for (int e = 0; e < 3; ++e) {
                unsigned a = faces[f + e], c = faces[f + (e + 1) % 3];
                unique.insert({a < c ? a : c, a < c ? c : a});
            }
        numOfSprings = int(unique.size());
        springs = new Spring*[numOfSprings];
        int s = 0;
        for (const auto& [a, c] : unique) {
            const double length = (masses[a]->position - masses[c]->position).length();
            springs[s++] = new Spring(masses[a], masses[c], k, length, b);
        }
    }
    ~Model() {
        for (int i = 0; i < numOfMasses; i++) delete masses[i];
        for (int i = 0; i < numOfSprings; i++) delete springs[i];
        delete[] masses;
        delete[] springs;
    }
    Model(const Model&) = delete;
    Model& operator=(const Model&) = delete;

    void step(double dt, const Vector3D& gravity, double airFriction) {
        for (int i = 0; i < numOfMasses; i++) masses[i]->init();
        for (int i = 0; i < numOfSprings; i++) springs[i]->solve();
        for (int i = 0; i < numOfMasses; i++) {
            masses[i]->applyForce(gravity * masses[i]->mass);
            masses[i]->applyForce(-masses[i]->velocity * airFriction);
        }
        for (int i = 0; i < numOfMasses; i++) masses[i]->simulate(dt);
    }

    int numOfMasses, numOfSprings;
    Mass** masses;
    Spring** springs;
};

}  // namespace naive
