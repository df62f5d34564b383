; Conformal post-processor
; part: 3-turn helix
; machine: 4-axis rotary mandrel (A about X) [rotary_mandrel]
; dialect: marlin
; tools: T0
; estimated time: 0:00:12 (11.5 s)
; material: PLA, 45.237 mm3 deposited by E words (filament 1.75 mm), 0.000 J cured
; tolerance: 0.01 mm, 0.05 deg; 2 segments, 302 points, 3 blocks
G21
G90
M83
M104 S210
G28
M109 S210
G0 X5 Y0 Z25 A0
G0 Z20
G1 X11 A1080 F31.8322 E18.80743
M400
M107
M104 S0
