// Vessel templates, copied from the service's --demo profiles. The form
// prefers the live demo vessels when the server has them (same names).

export const SURVEYOR_ROV = {
  "name": "Surveyor ROV",
  "kind": "rov6",
  "dofs": [
    "surge",
    "sway",
    "heave",
    "roll",
    "pitch",
    "yaw"
  ],
  "inputs": {
    "kind": "generalized_forces"
  },
  "limits": {
    "surge": {
      "max_velocity": 2.212111111111111,
      "max_force": 10000.0,
      "max_force_rate": 5000.0,
      "max_accel": 0.3,
      "time_constant_s": 4.0
    },
    "sway": {
      "max_velocity": 0.7716666666666667,
      "max_force": 6000.0,
      "max_force_rate": 3000.0,
      "max_accel": 0.3,
      "time_constant_s": 3.0
    },
    "heave": {
      "max_velocity": 0.7716666666666667,
      "max_force": 8000.0,
      "max_force_rate": 4000.0,
      "max_accel": 0.3,
      "time_constant_s": 3.0
    },
    "roll": {
      "max_velocity": 0.3,
      "max_force": 5000.0,
      "max_force_rate": 2500.0,
      "max_accel": 0.3,
      "time_constant_s": 1.5
    },
    "pitch": {
      "max_velocity": 0.3,
      "max_force": 5000.0,
      "max_force_rate": 2500.0,
      "max_accel": 0.3,
      "time_constant_s": 1.5
    },
    "yaw": {
      "max_velocity": 0.3,
      "max_force": 5000.0,
      "max_force_rate": 2500.0,
      "max_accel": 0.3,
      "time_constant_s": 2.0
    }
  },
  "controller_rate_hz": 20.0,
  "logger_rate_hz": 10.0
};

export const SUPPLY_VESSEL = {
  "name": "Supply vessel (Fossen et al. 1995)",
  "kind": "dp3",
  "dofs": [
    "surge",
    "sway",
    "yaw"
  ],
  "inputs": {
    "kind": "thrusters",
    "thrusters": [
      {
        "name": "port main propeller",
        "kind": "main",
        "max_command": 1.0,
        "max_rate": 0.1
      },
      {
        "name": "starboard main propeller",
        "kind": "main",
        "max_command": 1.0,
        "max_rate": 0.1
      },
      {
        "name": "aft tunnel thruster I",
        "kind": "tunnel",
        "max_command": 1.0,
        "max_rate": 0.1
      },
      {
        "name": "aft tunnel thruster II",
        "kind": "tunnel",
        "max_command": 1.0,
        "max_rate": 0.1
      },
      {
        "name": "bow tunnel thruster",
        "kind": "tunnel",
        "max_command": 1.0,
        "max_rate": 0.1
      },
      {
        "name": "bow azimuth thruster",
        "kind": "azimuth",
        "max_command": 1.0,
        "max_rate": 0.1
      }
    ],
    "configuration": [
      [
        1.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0
      ],
      [
        0.0,
        0.0,
        1.0,
        1.0,
        1.0,
        1.0
      ],
      [
        0.0472,
        -0.0472,
        -0.4108,
        -0.3858,
        0.4554,
        0.3373
      ]
    ]
  },
  "limits": {
    "surge": {
      "max_velocity": 4.0,
      "max_force": 1300000.0,
      "max_force_rate": 130000.0,
      "time_constant_s": 87.64272293177328
    },
    "sway": {
      "max_velocity": 1.0,
      "max_force": 550000.0,
      "max_force_rate": 55000.0,
      "time_constant_s": 44.37959536991068
    },
    "yaw": {
      "max_velocity": 0.035,
      "max_force": 16000000.0,
      "max_force_rate": 1600000.0,
      "time_constant_s": 11.478742130273439
    }
  },
  "controller_rate_hz": 1.0,
  "logger_rate_hz": 1.0
};

export const BLANK_ROV = {
  name: '',
  kind: 'rov6',
  dofs: ['surge', 'sway', 'heave', 'roll', 'pitch', 'yaw'],
  inputs: { kind: 'generalized_forces' },
  limits: {},
  controller_rate_hz: 20,
  logger_rate_hz: 10,
};
