"""A Firefly-like hexacopter: its URDF, rotor mixer, motor lag and cascaded controller.

Each rotor's thrust ``k_f w^2`` is applied as a force at the rotor; the rotors' drag torques
``+-k_m f`` give the yaw. The controller is a cascade: position error -> desired velocity ->
desired acceleration (tilt- and acceleration-limited) -> desired attitude and collective
thrust -> attitude error (on SO(3)) -> desired body rates -> torques -> six rotor thrusts.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet as pb

from astralis_des.mission.spec import HexacopterSpec
from astralis_des.physics.client import GRAVITY, PhysicsClient, quiet_c_output
from astralis_des.world.geometry import FloatArray

Vec = tuple[float, float, float] | FloatArray
ROTORS = 6
KP_POS = 1.2  # 1/s: position error -> velocity
KV = 3.0  # 1/s: velocity error -> acceleration
K_ATT = (7.0, 7.0, 2.0)  # 1/s: attitude error -> body rate
K_RATE = (22.0, 22.0, 8.0)  # 1/s: rate error -> angular acceleration
_NEG_K_ATT = tuple(-k for k in K_ATT)


def write_urdf(spec: HexacopterSpec, folder: Path) -> Path:
    """A one-link URDF: mass, inertia and a cylinder spanning the rotor tips."""
    ixx, iyy, izz = spec.inertia
    path = folder / "hexacopter.urdf"
    path.write_text(f"""<?xml version="1.0"?>
<robot name="hexacopter">
  <link name="base_link">
    <inertial>
      <origin xyz="0 0 0"/>
      <mass value="{spec.mass}"/>
      <inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/>
    </inertial>
    <collision>
      <geometry><cylinder radius="{spec.radius}" length="0.12"/></geometry>
    </collision>
  </link>
</robot>
""", encoding="utf-8")
    return path


class Hexacopter:
    """One hexacopter body in a client, and its controller."""

    def __init__(self, client: PhysicsClient, spec: HexacopterSpec, urdf: Path,
                 start: FloatArray, control_period: float) -> None:
        self.client = client
        self.spec = spec
        self.period = control_period
        with quiet_c_output():
            self.body = int(client.call("loadURDF", str(urdf), list(map(float, start)),
                                        flags=pb.URDF_USE_IMPLICIT_CYLINDER))
        client.call("changeDynamics", self.body, -1, linearDamping=0.0, angularDamping=0.0)
        angles = np.deg2rad(30.0 + 60.0 * np.arange(ROTORS))
        self.rotors = spec.arm_length * np.column_stack(
            [np.cos(angles), np.sin(angles), np.zeros(ROTORS)])
        self.spin = np.array([1.0, -1.0] * (ROTORS // 2))  # alternate: yaw from drag torques
        alloc = np.vstack([np.ones(ROTORS), self.rotors[:, 1], -self.rotors[:, 0],
                           self.spin * spec.moment_constant])
        self.mix = np.linalg.pinv(alloc)
        self.max_thrust = spec.thrust_constant * spec.max_rotor_speed**2
        hover = math.sqrt(spec.mass * GRAVITY / ROTORS / spec.thrust_constant)
        self.tilt = math.tan(math.radians(spec.max_tilt_deg))
        lag = spec.motor_time_constant
        self.motor_alpha = 1.0 if lag == 0 else 1.0 - math.exp(-control_period / lag)
        self.max_speed = 3.0
        self.max_horizontal = min(spec.max_accel, GRAVITY * self.tilt)
        # plain floats (numpy's scalars cost ten times more each; the arithmetic is the same)
        self._geometry = [(*self.mix[i].tolist(), float(self.rotors[i, 0]),
                           float(self.rotors[i, 1]), float(self.spin[i])) for i in range(ROTORS)]
        self._mass, self._inertia = spec.mass, tuple(spec.inertia)
        self._kf, self._km = spec.thrust_constant, spec.moment_constant
        self._rate_gains = tuple(j * k for j, k in zip(spec.inertia, K_RATE, strict=True))
        self.hover_speed = hover
        self.rotor_speed = [hover] * ROTORS

    def state(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Position, rotation matrix (body to world), velocity, body angular rate."""
        pos, quat = self.client.base_pose(self.body)
        lin, ang = self.client.base_velocity(self.body)
        rot = np.array(pb.getMatrixFromQuaternion(quat)).reshape(3, 3)
        return np.array(pos), rot, np.array(lin), rot.T @ np.array(ang)

    def position(self) -> FloatArray:
        """Where it is (read every few control periods)."""
        pos, _ = self.client.base_pose(self.body)
        return np.array(pos)

    def tilt_deg(self) -> float:
        """Degrees between the body's z axis and the vertical."""
        _, (qx, qy, _, _) = self.client.base_pose(self.body)
        return math.degrees(math.acos(min(max(1.0 - 2.0 * (qx * qx + qy * qy), -1.0), 1.0)))

    def control(self, p_ref: Vec, v_ref: Vec, yaw_ref: float = 0.0,
                a_ref: Vec = (0.0, 0.0, 0.0)) -> float:
        """One controller update; the rotor forces hold until the next one. Returns how far
        the craft is from ``p_ref`` (m).

        Written on plain floats: for 3-vectors, numpy's call overhead costs more than the
        arithmetic (``np.cross`` alone takes 20 us); the spec's numbers are read into locals
        once (each UAV runs this every control period).
        """
        client, body = self.client, self.body
        cid = client.id
        (px, py, pz), quat = client.base_pose(body)
        (vx, vy, vz), (wx, wy, wz) = client.base_velocity(body)
        r00, r01, r02, r10, r11, r12, r20, r21, r22 = pb.getMatrixFromQuaternion(quat)
        mass, (jx, jy, jz), max_speed = self._mass, self._inertia, self.max_speed
        # position -> velocity -> acceleration, with speed, tilt and climb limits
        dx = v_ref[0] + KP_POS * (p_ref[0] - px)
        dy = v_ref[1] + KP_POS * (p_ref[1] - py)
        dz = v_ref[2] + KP_POS * (p_ref[2] - pz)
        speed = math.sqrt(dx * dx + dy * dy + dz * dz)
        if speed > max_speed:
            k = max_speed / speed
            dx, dy, dz = dx * k, dy * k, dz * k
        # the reference's own acceleration, fed forward: without it a cascade of two
        # proportional loops lags a reference speeding up at a by a / (KP_POS * KV) metres
        ax = a_ref[0] + KV * (dx - vx)
        ay = a_ref[1] + KV * (dy - vy)
        az = a_ref[2] + KV * (dz - vz)
        horizontal = math.hypot(ax, ay)
        if horizontal > self.max_horizontal:
            k = self.max_horizontal / horizontal
            ax, ay = ax * k, ay * k
        az = _clamp(az, -0.5 * GRAVITY, 0.5 * GRAVITY)
        fx, fy, fz = mass * ax, mass * ay, mass * (az + GRAVITY)
        thrust = fx * r02 + fy * r12 + fz * r22
        thrust = 0.0 if thrust < 0.0 else thrust  # max(thrust, 0.0), without the call
        norm = math.sqrt(fx * fx + fy * fy + fz * fz)
        zx, zy, zz = fx / norm, fy / norm, fz / norm
        # desired attitude: body z along the force, heading yaw_ref
        cx, cy = math.cos(yaw_ref), math.sin(yaw_ref)
        yx, yy, yz = -zz * cy, zz * cx, zx * cy - zy * cx  # z_d x (cos, sin, 0)
        norm = math.sqrt(yx * yx + yy * yy + yz * yz)
        yx, yy, yz = yx / norm, yy / norm, yz / norm
        xx, xy, xz = yy * zz - yz * zy, yz * zx - yx * zz, yx * zy - yy * zx
        # attitude error e = vee(Rd^T R - R^T Rd) / 2, from the columns of both matrices
        e0 = 0.5 * ((zx * r01 + zy * r11 + zz * r21) - (yx * r02 + yy * r12 + yz * r22))
        e1 = 0.5 * ((xx * r02 + xy * r12 + xz * r22) - (zx * r00 + zy * r10 + zz * r20))
        e2 = 0.5 * ((yx * r00 + yy * r10 + yz * r20) - (xx * r01 + xy * r11 + xz * r21))
        # body rates and torques
        bx = r00 * wx + r10 * wy + r20 * wz
        by = r01 * wx + r11 * wy + r21 * wz
        bz = r02 * wx + r12 * wy + r22 * wz
        (gx, gy, gz), (ex_, ey_, ez_) = self._rate_gains, _NEG_K_ATT
        w1 = gx * (ex_ * e0 - bx) + (by * jz * bz - bz * jy * by)
        w2 = gy * (ey_ * e1 - by) + (bz * jx * bx - bx * jz * bz)
        w3 = gz * (ez_ * e2 - bz) + (bx * jy * by - by * jx * bx)
        # the rotors: mix (thrust, torques) to rotor thrusts through the motors' lag. Each
        # pushes along the body's z at its arm's end; applied as their sum at the centre of
        # mass and the sum of their moments about it plus the rotors' drag torque (what
        # PyBullet makes of a force at a point: two calls instead of seven)
        kf, ceiling, alpha, speeds = self._kf, self.max_thrust, self.motor_alpha, \
            self.rotor_speed
        sqrt = math.sqrt
        drag = total = 0.0
        mx = my = mz = 0.0  # sum of thrust x the arm's end, relative to the centre of mass
        for i, (m0, m1, m2, m3, ox, oy, spin) in enumerate(self._geometry):
            wanted = m0 * thrust + m1 * w1 + m2 * w2 + m3 * w3
            wanted = 0.0 if wanted < 0.0 else wanted  # min(max(wanted, 0), ceiling)
            wanted = ceiling if ceiling < wanted else wanted
            speed = speeds[i]
            speed += (sqrt(wanted / kf) - speed) * alpha
            speeds[i] = speed
            f = kf * speed * speed
            drag += spin * f
            total += f
            mx += f * (r00 * ox + r01 * oy)
            my += f * (r10 * ox + r11 * oy)
            mz += f * (r20 * ox + r21 * oy)
        drag *= self._km
        torque = (my * r22 - mz * r12 + r02 * drag, mz * r02 - mx * r22 + r12 * drag,
                  mx * r12 - my * r02 + r22 * drag)
        pb.applyExternalForce(body, -1, (r02 * total, r12 * total, r22 * total), (px, py, pz),
                              pb.WORLD_FRAME, physicsClientId=cid)
        pb.applyExternalTorque(body, -1, torque, pb.WORLD_FRAME, physicsClientId=cid)
        ex, ey, ez = p_ref[0] - px, p_ref[1] - py, p_ref[2] - pz
        return math.sqrt(ex * ex + ey * ey + ez * ez)


def _clamp(value: float, low: float, high: float) -> float:
    """``min(max(value, low), high)`` to the bit (signed zeros included), without the calls."""
    value = low if low > value else value
    return high if high < value else value
