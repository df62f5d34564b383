; Conformal post-processor
; part: flat square
; machine: Plain 3-axis [three_axis]
; dialect: marlin
; tools: T0
; estimated time: 0:00:04 (4.2 s)
; material: PLA, 6.400 mm3 deposited by E words (filament 1.75 mm), 0.000 J cured
; tolerance: 0.01 mm, 0.05 deg; 2 segments, 7 points, 6 blocks
G21
G90
M83
M140 S60
M104 S210
G28
M190 S60
M109 S210
G0 X50 Y50 Z10.3
G0 Z0.3
; extruder on: E words on the moves drive it
G1 X70 F1200 E0.6652
G1 Y70 E0.6652
G1 X50 E0.6652
G1 Y50 E0.6652
; extruder off: E words on the moves drive it
M400
M107
M104 S0
M140 S0
