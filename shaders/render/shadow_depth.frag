#version 450 core
// A shadow map's depth pass: the depth buffer is the output, no colour is written.
void main() {
}
