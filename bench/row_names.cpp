// bench/row_names.cpp - the names of collide_bench's rows (row_names.hpp).
#include "row_names.hpp"

namespace collide_bench {
namespace {

/// The end of every name but a schedule row's: "/t:T/n:N".
std::string threads_and_n(int threads, std::size_t n) {
  return "/t:" + std::to_string(threads) + "/n:" + std::to_string(n);
}

}  // namespace

std::string model_tag(collide::Model model, bool friction) {
  return std::string(collide::to_string(model)) + (friction ? "+mu" : "");
}

const char* layout_row_name(LayoutRow layout) {
  return layout == LayoutRow::soa ? "soa" : layout == LayoutRow::packed ? "packed" : "records";
}

std::string solve_name(Kind kind, const char* precision, collide::Path path, int threads, std::size_t n) {
  return std::string("solve/") + kind_name(kind) + "/" + precision + "/" + collide::to_string(path) +
         threads_and_n(threads, n);
}

std::string isa_name(Kind kind, const char* precision, collide::Isa isa, int threads, std::size_t n) {
  return std::string("isa/") + kind_name(kind) + "/" + precision + "/" + collide::to_string(isa) +
         threads_and_n(threads, n);
}

std::string model_name(Kind kind, collide::Model model, bool friction, const char* precision, int threads,
                       std::size_t n) {
  return std::string("model/") + kind_name(kind) + "/" + model_tag(model, friction) + "/" + precision + "/simd" +
         threads_and_n(threads, n);
}

std::string accurate_name(Kind kind, collide::Model model, bool friction, const char* precision, int threads,
                          std::size_t n) {
  return std::string("accurate/") + kind_name(kind) + "/" + model_tag(model, friction) + "/" + precision + "/simd" +
         threads_and_n(threads, n);
}

std::string layout_name(Kind kind, collide::Model model, bool friction, const char* precision, LayoutRow layout,
                        int threads, std::size_t n) {
  return std::string("layout/") + kind_name(kind) + "/" + model_tag(model, friction) + "/" + precision + "/" +
         layout_row_name(layout) + threads_and_n(threads, n);
}

std::string twin_name(collide::Model model, bool friction, const char* precision, int threads, std::size_t n) {
  return "twin/pairs/" + model_tag(model, friction) + "/" + precision + threads_and_n(threads, n);
}

std::string packed_twin_name(Kind kind, collide::Model model, const char* precision, int threads, std::size_t n) {
  return std::string("twin/packed/") + kind_name(kind) + "/" + collide::to_string(model) + "/" + precision +
         threads_and_n(threads, n);
}

std::string textbook_name(Kind kind, const char* precision, std::size_t n) {
  return std::string("textbook/") + kind_name(kind) + "/" + precision + threads_and_n(1, n);
}

std::string schedule_name(Kind kind, const char* precision, std::size_t n, collide::Order order) {
  return std::string("schedule/") + kind_name(kind) + "/" + precision +
         (order == collide::Order::colour ? "/colour" : "") + "/n:" + std::to_string(n);
}

std::string order_name(Kind kind, const char* precision, collide::Order order, int passes, int threads, std::size_t n) {
  return std::string("order/") + kind_name(kind) + "/" + precision + "/" + collide::to_string(order) +
         "/passes:" + std::to_string(passes) + threads_and_n(threads, n);
}

std::string iterate_name(Kind kind, const char* precision, collide::Order order, collide::Iteration iteration,
                         int passes, int threads, std::size_t n, bool warm) {
  return std::string("iterate/") + kind_name(kind) + "/" + precision + "/" + collide::to_string(order) + "/" +
         collide::to_string(iteration) + (warm ? "/warm" : "") + "/passes:" + std::to_string(passes) +
         threads_and_n(threads, n);
}

std::string order_twin_name(Kind kind, const char* precision, collide::Order order, int threads, std::size_t n) {
  return std::string("order_twin/") + kind_name(kind) + "/" + precision + "/" + collide::to_string(order) +
         threads_and_n(threads, n);
}

}  // namespace collide_bench
