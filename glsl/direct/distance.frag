#version 430
in vec3 vPosition;
uniform vec3 samplePoint;
layout(location = 0) out float outDistance;
void main() { outDistance = distance(vPosition, samplePoint); }
